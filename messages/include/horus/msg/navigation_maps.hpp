// The navigation domain's maps (part of horus/msg/navigation.hpp, which includes this file):
// OccupancyGrid and CostMap, variable-size (their cells live in a std::vector) and serialized.
// Grid cells are addressed (gx, gy) with gx along world x, gy along world y, stored row-major
// (index gy * width + gx). Units as in geometry.hpp.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "horus/fixed_string.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// A 2D occupancy map (variable-size). Cell values: -1 unknown, 0 free ...
/// 100 occupied (a probability in percent). The map is axis-aligned: origin is
/// the world position of the outer corner of cell (0, 0); as in HORUS,
/// origin.theta is carried but NOT applied by the coordinate conversions.
struct OccupancyGrid {
  /// Largest encoded grid a Topic<OccupancyGrid> carries unless told otherwise (a 2000x2000 map).
  static constexpr std::size_t kDefaultSlotBytes = std::size_t{4} << 20;
  static constexpr std::int8_t UNKNOWN = -1;
  static constexpr std::int8_t FREE = 0;
  static constexpr std::int8_t OCCUPIED = 100;
  /// is_free(): 0 <= value < 50; is_occupied(): value >= 50 (HORUS thresholds).
  static constexpr std::int8_t OCCUPIED_THRESHOLD = 50;

  float resolution{0.05f};  ///< m per cell (HORUS default 0.05)
  std::uint32_t width{};    ///< cells along x
  std::uint32_t height{};   ///< cells along y
  Pose2D origin{};          ///< corner of cell (0, 0) in the world (theta ignored, see above)
  std::vector<std::int8_t> data{};  ///< width * height cells, row-major (gy * width + gx)
  std::array<char, 32> frame_id{};  ///< NUL-terminated, at most 31 characters
  std::array<char, 64> metadata{};  ///< free text, NUL-terminated, at most 63 characters
  std::uint64_t timestamp_ns{};

  /// The spec's OccupancyGrid::new(width, height, resolution, origin): every
  /// cell unknown (-1); the timestamp is left 0.
  static OccupancyGrid make(std::uint32_t width_cells, std::uint32_t height_cells, float resolution_m,
                            const Pose2D& origin_pose) {
    OccupancyGrid g{};
    g.resolution = resolution_m;
    g.width = width_cells;
    g.height = height_cells;
    g.origin = origin_pose;
    g.data.assign(static_cast<std::size_t>(width_cells) * height_cells, UNKNOWN);
    return g;
  }

  /// The cell containing world point (x, y) in metres: floor((x - origin.x) /
  /// resolution + 1e-6), likewise for y. The 1e-6 cell epsilon (HORUS's) makes a
  /// point on a cell boundary belong to the upper cell despite rounding
  /// (0.5 at 0.1 m is cell 5). nullopt outside [0, width) x [0, height), for a
  /// NaN or infinite coordinate, and when resolution is not a positive number.
  std::optional<std::pair<std::uint32_t, std::uint32_t>> world_to_grid(double x, double y) const noexcept {
    const double res = static_cast<double>(resolution);
    if (!(res > 0.0) || !std::isfinite(res)) return std::nullopt;
    const double gx = std::floor((x - origin.x) / res + kCellEpsilon);
    const double gy = std::floor((y - origin.y) / res + kCellEpsilon);
    // Written so that NaN fails every comparison.
    if (!(gx >= 0.0 && gx < static_cast<double>(width) && gy >= 0.0 && gy < static_cast<double>(height)))
      return std::nullopt;
    return std::pair{static_cast<std::uint32_t>(gx), static_cast<std::uint32_t>(gy)};
  }

  /// World position (m) of the centre of cell (gx, gy), or nullopt outside the grid.
  std::optional<std::pair<double, double>> grid_to_world(std::uint32_t gx, std::uint32_t gy) const noexcept {
    if (gx >= width || gy >= height) return std::nullopt;
    const double res = static_cast<double>(resolution);
    return std::pair{origin.x + (static_cast<double>(gx) + 0.5) * res,
                     origin.y + (static_cast<double>(gy) + 0.5) * res};
  }

  /// Index of cell (gx, gy) into data, or nullopt outside the grid or beyond
  /// the end of data (a malformed message may carry fewer cells).
  std::optional<std::size_t> cell_index(std::uint32_t gx, std::uint32_t gy) const noexcept {
    if (gx >= width || gy >= height) return std::nullopt;
    const std::size_t i = static_cast<std::size_t>(gy) * width + gx;
    if (i >= data.size()) return std::nullopt;
    return i;
  }

  /// The value of cell (gx, gy), or nullopt outside the grid.
  std::optional<std::int8_t> occupancy(std::uint32_t gx, std::uint32_t gy) const noexcept {
    if (const auto i = cell_index(gx, gy)) return data[*i];
    return std::nullopt;
  }

  /// Sets cell (gx, gy). Returns false, changing nothing, outside the grid or
  /// when value is not in -1..100 (HORUS clamps such values instead).
  bool set_occupancy(std::uint32_t gx, std::uint32_t gy, std::int8_t value) noexcept {
    if (value < UNKNOWN || value > OCCUPIED) return false;
    const auto i = cell_index(gx, gy);
    if (!i) return false;
    data[*i] = value;
    return true;
  }

  /// World point (m) lies in a known cell with 0 <= value < 50. Unknown cells
  /// and points outside the grid are not free.
  bool is_free(double x, double y) const noexcept {
    const auto v = world_occupancy(x, y);
    return v && *v >= 0 && *v < OCCUPIED_THRESHOLD;
  }
  /// World point (m) lies in a cell with value >= 50. Unknown cells and points
  /// outside the grid are not occupied (check is_free() to plan conservatively).
  bool is_occupied(double x, double y) const noexcept {
    const auto v = world_occupancy(x, y);
    return v && *v >= OCCUPIED_THRESHOLD;
  }

  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }
  constexpr bool set_metadata(std::string_view text) noexcept { return set_fixed_str(metadata, text); }
  constexpr std::string_view metadata_str() const noexcept { return fixed_str_view(metadata); }

  /// "OccupancyGrid(200x200 @ 0.05 m, 40000 cells)".
  std::string log_summary() const;

  friend bool operator==(const OccupancyGrid&, const OccupancyGrid&) = default;

  static constexpr double kCellEpsilon = 1e-6;  ///< in cells, see world_to_grid()

 private:
  std::optional<std::int8_t> world_occupancy(double x, double y) const noexcept {
    if (const auto cell = world_to_grid(x, y)) return occupancy(cell->first, cell->second);
    return std::nullopt;
  }
};
HORUS_REFLECT(OccupancyGrid, resolution, width, height, origin, data, frame_id, metadata, timestamp_ns)

// ---------------------------------------------------------------------------
/// An inflated cost grid over an OccupancyGrid (variable-size); costs[i]
/// belongs to occupancy_grid.data[i]. Costs: 0 free, 1..lethal_cost-1 near an
/// obstacle, lethal_cost (253) in an obstacle, 255 unknown.
///
/// compute_costs(), as HORUS:
///  1. Base cost per cell from its occupancy v: -1 (unknown) -> 255;
///     v >= 65 -> lethal_cost; otherwise max(2 v, 0) (so 0..64 -> 0..128).
///     Cells missing from a short data vector count as unknown.
///  2. Inflation: every cell whose base cost is below lethal_cost takes
///     max(base, floor((lethal_cost - 1) * (1 - d / R)^cost_scaling_factor))
///     where R = inflation_radius and d (m) is the distance between cell centres
///     to the nearest cell with base cost >= lethal_cost (occupied AND unknown
///     cells, as in HORUS) among the cells at most ceil(R / resolution) cells
///     away along x and y, when d <= R. So a cell next to an obstacle gets up to
///     252, a cell at d = R gets 0, cells beyond R are untouched. This is a
///     power law (HORUS's formula), not ROS's exp(-k (d - r_inscribed)); there
///     is no inscribed (254) cost. Computed in single precision as HORUS.
///     No inflation when R <= 0 (or NaN) or resolution is not a positive number.
struct CostMap {
  /// Largest encoded cost map a Topic<CostMap> carries unless told otherwise (a 2000x2000 map).
  static constexpr std::size_t kDefaultSlotBytes = std::size_t{8} << 20;
  static constexpr std::uint8_t COST_FREE = 0;
  static constexpr std::uint8_t COST_LETHAL = 253;
  static constexpr std::uint8_t COST_UNKNOWN = 255;
  /// Occupancy at or above which a cell is an obstacle (lethal).
  static constexpr std::int8_t LETHAL_OCCUPANCY = 65;

  OccupancyGrid occupancy_grid{};
  std::vector<std::uint8_t> costs{};  ///< one per cell, row-major like occupancy_grid.data
  float inflation_radius{0.55f};      ///< m (HORUS default 0.55)
  float cost_scaling_factor{10.0f};   ///< exponent of the decay (HORUS default 10)
  std::uint8_t lethal_cost{COST_LETHAL};

  /// The spec's CostMap::from_occupancy_grid(grid, inflation_radius): takes the
  /// grid, default cost_scaling_factor 10 and lethal_cost 253, and runs
  /// compute_costs().
  static CostMap from_occupancy_grid(OccupancyGrid grid, float inflation_radius_m) {
    CostMap map{};
    map.occupancy_grid = std::move(grid);
    map.inflation_radius = inflation_radius_m;
    map.compute_costs();
    return map;
  }

  /// Recomputes costs from occupancy_grid and the parameters (see the type comment).
  void compute_costs() {
    const std::size_t w = occupancy_grid.width;
    const std::size_t h = occupancy_grid.height;
    const std::size_t n = w * h;
    const auto& occ = occupancy_grid.data;
    costs.assign(n, COST_UNKNOWN);
    for (std::size_t i = 0; i < std::min(n, occ.size()); ++i) costs[i] = base_cost(occ[i]);
    inflate(w, h);
  }

  /// The cost at world point (x, y) in metres. Outside the grid: lethal_cost
  /// (as HORUS: unmapped space is not drivable). nullopt only when costs is
  /// shorter than the grid (not computed, or a malformed message).
  std::optional<std::uint8_t> cost(double x, double y) const noexcept {
    const auto cell = occupancy_grid.world_to_grid(x, y);
    if (!cell) return lethal_cost;
    const std::size_t i = static_cast<std::size_t>(cell->second) * occupancy_grid.width + cell->first;
    if (i >= costs.size()) return std::nullopt;
    return costs[i];
  }

  /// "CostMap(200x200 @ 0.05 m, inflation 0.55 m, 12 lethal, 340 inflated, 500 unknown)".
  std::string log_summary() const;

  friend bool operator==(const CostMap&, const CostMap&) = default;

 private:
  std::uint8_t base_cost(std::int8_t v) const noexcept {
    if (v == OccupancyGrid::UNKNOWN) return COST_UNKNOWN;
    if (v >= LETHAL_OCCUPANCY) return lethal_cost;
    return static_cast<std::uint8_t>(std::max(2 * static_cast<int>(v), 0));
  }

  void inflate(std::size_t w, std::size_t h) {
    const float res = occupancy_grid.resolution;
    const float radius = inflation_radius;
    if (!(radius > 0.0f) || !(res > 0.0f) || !std::isfinite(res) || w == 0 || h == 0) return;
    // Window half-width in cells; beyond the grid size it changes nothing.
    const double cells = std::ceil(static_cast<double>(radius) / static_cast<double>(res));
    const long k = static_cast<long>(std::min(cells, static_cast<double>(std::max(w, h))));
    const std::vector<std::uint8_t> base = costs;
    const auto is_source = [&](std::size_t i) { return base[i] >= lethal_cost; };
    std::vector<float> nearest(base.size(), std::numeric_limits<float>::infinity());
    const long lw = static_cast<long>(w), lh = static_cast<long>(h);
    for (long y = 0; y < lh; ++y) {
      for (long x = 0; x < lw; ++x) {
        const std::size_t s = static_cast<std::size_t>(y * lw + x);
        if (!is_source(s)) continue;
        // The nearest source of any cell has a non-source 4-neighbour (a closer
        // one would otherwise exist), so interior sources can be skipped.
        const bool frontier = (x > 0 && !is_source(s - 1)) || (x + 1 < lw && !is_source(s + 1)) ||
                              (y > 0 && !is_source(s - w)) || (y + 1 < lh && !is_source(s + w));
        if (!frontier) continue;
        for (long ny = std::max(0L, y - k); ny <= std::min(lh - 1, y + k); ++ny) {
          for (long nx = std::max(0L, x - k); nx <= std::min(lw - 1, x + k); ++nx) {
            const std::size_t t = static_cast<std::size_t>(ny * lw + nx);
            if (is_source(t)) continue;
            const long dx = nx - x, dy = ny - y;
            const float d = std::sqrt(static_cast<float>(dx * dx + dy * dy)) * res;
            nearest[t] = std::min(nearest[t], d);
          }
        }
      }
    }
    const float cap = static_cast<float>(lethal_cost) - 1.0f;
    for (std::size_t i = 0; i < base.size(); ++i) {
      if (is_source(i) || !(nearest[i] <= radius)) continue;
      const float factor = 1.0f - nearest[i] / radius;
      float c = std::min(cap * std::pow(factor, cost_scaling_factor), cap);
      if (!(c > 0.0f)) c = 0.0f;  // also NaN
      costs[i] = std::max(costs[i], static_cast<std::uint8_t>(c));
    }
  }
};
HORUS_REFLECT(CostMap, occupancy_grid, costs, inflation_radius, cost_scaling_factor, lethal_cost)

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(OccupancyGrid, CostMap)

}  // namespace horus::msg

HORUS_API_END
