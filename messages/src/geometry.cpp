// The functions of horus/msg/geometry.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/geometry.hpp"

#include <fmt/format.h>

#include <string>
#include <string_view>

namespace horus::msg {

std::string PoseWithCovariance::log_summary() const {
  const auto pv = position_variance();
  const auto ov = orientation_variance();
  return fmt::format(
      "PoseWithCovariance({}, position ({:.2f}, {:.2f}, {:.2f}) m, var xyz ({:.3g}, {:.3g}, {:.3g}) m^2, "
      "var rpy ({:.3g}, {:.3g}, {:.3g}) rad^2)",
      frame_id_str().empty() ? std::string_view("no frame") : frame_id_str(), pose.position.x, pose.position.y,
      pose.position.z, pv[0], pv[1], pv[2], ov[0], ov[1], ov[2]);
}

std::string TwistWithCovariance::log_summary() const {
  const auto lv = linear_variance();
  const auto av = angular_variance();
  return fmt::format(
      "TwistWithCovariance({}, linear ({:.2f}, {:.2f}, {:.2f}) m/s, angular ({:.2f}, {:.2f}, {:.2f}) rad/s, "
      "var linear ({:.3g}, {:.3g}, {:.3g}), var angular ({:.3g}, {:.3g}, {:.3g}))",
      frame_id_str().empty() ? std::string_view("no frame") : frame_id_str(), twist.linear[0], twist.linear[1],
      twist.linear[2], twist.angular[0], twist.angular[1], twist.angular[2], lv[0], lv[1], lv[2], av[0], av[1],
      av[2]);
}

}  // namespace horus::msg
