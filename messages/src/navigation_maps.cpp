// The functions of horus/msg/navigation_maps.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/navigation_maps.hpp"

#include <fmt/format.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace horus::msg {

std::string OccupancyGrid::log_summary() const {
  return fmt::format("OccupancyGrid({}x{} @ {:g} m, {} cells)", width, height, static_cast<double>(resolution),
                     data.size());
}

std::string CostMap::log_summary() const {
  std::size_t lethal = 0, inflated = 0, unknown = 0;
  for (std::uint8_t c : costs) {
    if (c == COST_UNKNOWN) ++unknown;
    else if (c >= lethal_cost) ++lethal;
    else if (c > COST_FREE) ++inflated;
  }
  return fmt::format("CostMap({}x{} @ {:g} m, inflation {:g} m, {} lethal, {} inflated, {} unknown)",
                     occupancy_grid.width, occupancy_grid.height, static_cast<double>(occupancy_grid.resolution),
                     static_cast<double>(inflation_radius), lethal, inflated, unknown);
}

}  // namespace horus::msg
