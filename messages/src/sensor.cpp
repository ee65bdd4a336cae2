// The functions of horus/msg/sensor.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/sensor.hpp"

#include <fmt/format.h>

#include <cstddef>
#include <string>

#include "summary_list.hpp"

namespace horus::msg {

std::string LaserScan::log_summary() const {
  const auto closest = min_range();
  return fmt::format("LaserScan({} ranges, {} valid, min {}, fov {:.2f} rad)", ranges.size(), valid_count(),
                     closest ? fmt::format("{:.2f} m", *closest) : std::string("none"),
                     static_cast<double>(angle_max) - static_cast<double>(angle_min));
}

std::string Odometry::log_summary() const {
  return fmt::format("Odometry({} -> {}, x {:.2f} m, y {:.2f} m, theta {:.2f} rad, v {:.2f} m/s, w {:.2f} rad/s)",
                     frame_id_str(), child_frame_id_str(), pose.x, pose.y, pose.theta, twist.linear[0],
                     twist.angular[2]);
}

std::string JointState::log_summary() const {
  std::string out = fmt::format("JointState({} joints", count());
  if (count() > 0) out += ", positions in rad or m";
  detail::append_summary_list(out, count(),
                              [&](std::size_t i) { return fmt::format("{}={:.4g}", name_at(i), positions[i]); });
  return out;
}

std::string BatteryState::log_summary() const {
  std::string status;
  switch (power_supply_status) {
    case STATUS_UNKNOWN: status = "unknown"; break;
    case STATUS_CHARGING: status = "charging"; break;
    case STATUS_DISCHARGING: status = "discharging"; break;
    case STATUS_FULL: status = "full"; break;
    default: status = fmt::format("status {}", static_cast<int>(power_supply_status)); break;
  }
  return fmt::format("BatteryState({:.2f} V, {:.1f} %, {:.2f} A, {}, {:.1f} degC, {} cells)",
                     static_cast<double>(voltage), static_cast<double>(percentage), static_cast<double>(current),
                     status, static_cast<double>(temperature), static_cast<int>(cell_count));
}

std::string NavSatFix::log_summary() const {
  std::string fix;
  switch (status) {
    case STATUS_NO_FIX: fix = "no fix"; break;
    case STATUS_FIX: fix = "fix"; break;
    case STATUS_SBAS_FIX: fix = "SBAS fix"; break;
    case STATUS_GBAS_FIX: fix = "GBAS fix"; break;
    default: fix = fmt::format("status {}", static_cast<int>(status)); break;
  }
  return fmt::format("NavSatFix(lat {:.6f} deg, lon {:.6f} deg, alt {:.1f} m, {} sats, {}, hdop {:.1f})", latitude,
                     longitude, altitude, satellites_visible, fix, static_cast<double>(hdop));
}

}  // namespace horus::msg
