// The functions of horus/msg/navigation.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/navigation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <string>

namespace horus::msg {

std::string Path::log_summary() const {
  return fmt::format("Path({} waypoints, {:.1f} m)", count(), total_length);
}

std::string NavPath::log_summary() const {
  return fmt::format("NavPath({} waypoints, {:.1f} m)", count(), total_length);
}

std::string PathPlan::log_summary() const {
  return fmt::format("PathPlan({} waypoints, goal ({:.2f}, {:.2f}, {:.2f}))", count(), goal_pose[0], goal_pose[1],
                     goal_pose[2]);
}

std::string VelocityObstacles::log_summary() const {
  std::string out = fmt::format("VelocityObstacles({} obstacles", size());
  constexpr std::size_t kShown = 8;
  for (std::size_t i = 0; i < std::min(size(), kShown); ++i)
    out += fmt::format("{}{}", i == 0 ? ", ids " : ", ", obstacles[i].obstacle_id);
  if (size() > kShown) out += fmt::format(", +{} more", size() - kShown);
  out += ')';
  return out;
}

}  // namespace horus::msg
