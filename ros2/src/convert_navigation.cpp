// The navigation conversions (convert.hpp): odometry, occupancy grids, paths, and the joystick,
// diagnostics and clock messages a navigation stack reads beside them.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <string>

#include "cdr_io.hpp"
#include "horus/msg/diagnostics.hpp"
#include "horus/msg/input.hpp"
#include "horus/msg/navigation.hpp"
#include "horus/msg/sensor.hpp"
#include "horus/msg/time.hpp"

namespace horus::ros2::detail {
namespace {

// geometry_msgs/msg/Pose of a horus Pose2D: position (x, y, 0), the rotation theta about z
// (quaternion 0, 0, sin(theta / 2), cos(theta / 2)); back, theta is the quaternion's yaw and
// z, roll and pitch are dropped.
template <class S>
void nav_put_pose(Out<S>& o, const msg::Pose2D& p) {
  o.vector3(p.x, p.y, 0.0);
  o.num(0.0);
  o.vector3(0.0, std::sin(p.theta / 2.0), std::cos(p.theta / 2.0));
}
bool nav_get_pose(In& in, msg::Pose2D& p, std::string_view field) {
  std::array<double, 7> v{};  // position x, y, z; orientation x, y, z, w
  if (!in.run(v.data(), v.size(), field)) return false;
  const double x = v[3], y = v[4], z = v[5], w = v[6];
  p.x = v[0];
  p.y = v[1];
  p.theta = std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  return true;
}

struct OdometryOdometry {
  using Horus = msg::Odometry;
  static constexpr std::string_view kRos = "nav_msgs/msg/Odometry";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: pose.timestamp_ns and twist.timestamp_ns (the header's stamp is timestamp_ns); pose.position.z is "
      "0 and the orientation the rotation theta about z; an empty frame_id or child_frame_id is the rule's; "
      "from ROS 2: pose.position.z, roll and pitch (theta is the orientation's yaw); pose.timestamp_ns and "
      "twist.timestamp_ns are the header's stamp; frame ids over 31 characters are refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, frame_or(m.frame_id_str(), ctx.frame_id));
    o.string(frame_or(m.child_frame_id_str(), ctx.child_frame_id));
    nav_put_pose(o, m.pose);
    o.run(std::span<const double>(m.pose_covariance));
    o.run(std::span<const double>(m.twist.linear));
    o.run(std::span<const double>(m.twist.angular));
    o.run(std::span<const double>(m.twist_covariance));
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    if (!in.header(m.timestamp_ns, frame) ||
        !in.text(m.frame_id, frame, "header.frame_id", "horus::msg::Odometry.frame_id") ||
        !in.string(m.child_frame_id, "child_frame_id", "horus::msg::Odometry.child_frame_id") ||
        !nav_get_pose(in, m.pose, "pose.pose") || !in.run(m.pose_covariance.data(), 36, "pose.covariance") ||
        !in.run(m.twist.linear.data(), 3, "twist.twist.linear") ||
        !in.run(m.twist.angular.data(), 3, "twist.twist.angular") ||
        !in.run(m.twist_covariance.data(), 36, "twist.covariance"))
      return false;
    m.pose.timestamp_ns = m.timestamp_ns;
    m.twist.timestamp_ns = m.timestamp_ns;
    return true;
  }
};

struct OccupancyGridOccupancyGrid {
  using Horus = msg::OccupancyGrid;
  static constexpr std::string_view kRos = "nav_msgs/msg/OccupancyGrid";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: metadata; info.map_load_time is timestamp_ns, info.origin the pose (x, y, 0) turned theta about z; "
      "an empty frame_id is the rule's; from ROS 2: info.map_load_time, the origin's z, roll and pitch; metadata "
      "is empty; data of another size than width * height is refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, frame_or(m.frame_id_str(), ctx.frame_id));
    o.time(m.timestamp_ns);  // info.map_load_time
    o.num(m.resolution);
    o.num(m.width);
    o.num(m.height);
    nav_put_pose(o, m.origin);
    o.sequence(std::span<const std::int8_t>(m.data));
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    std::uint64_t load_time = 0;
    std::size_t n = 0;
    if (!in.header(m.timestamp_ns, frame) ||
        !in.text(m.frame_id, frame, "header.frame_id", "horus::msg::OccupancyGrid.frame_id") ||
        !in.time(load_time, "info.map_load_time") || !in.num(m.resolution, "info.resolution") ||
        !in.num(m.width, "info.width") || !in.num(m.height, "info.height") ||
        !nav_get_pose(in, m.origin, "info.origin") || !in.count(n, 1, "data"))
      return false;
    if (n != std::uint64_t{m.width} * m.height)
      return in.malformed("data", std::to_string(n) + " cells for a " + std::to_string(m.width) + "x" +
                                      std::to_string(m.height) + " grid");
    const auto* p = reinterpret_cast<const std::int8_t*>(in.r.here());
    m.data.assign(p, p + n);
    in.r.skip(n);
    m.metadata = {};
    return true;
  }
};

struct NavPathPath {
  using Horus = msg::NavPath;
  static constexpr std::string_view kRos = "nav_msgs/msg/Path";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: each waypoint's velocity, time_from_start, curvature and stop_required, the path's total_length, "
      "estimated_time and algorithm; each pose is stamped with the path's header; an empty frame_id is the rule's; "
      "from ROS 2: each pose's header and its z, roll and pitch; velocities, times and curvatures are 0, "
      "total_length the polyline's length; more than 256 poses are refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    const std::string_view frame = frame_or(m.frame_id_str(), ctx.frame_id);
    o.header(m.timestamp_ns, frame);
    const std::size_t n = m.count();
    o.count(n);
    for (std::size_t i = 0; i < n; ++i) {
      o.header(m.timestamp_ns, frame);
      nav_put_pose(o, m.waypoints[i].pose);
    }
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    std::size_t n = 0;
    if (!in.header(m.timestamp_ns, frame) ||
        !in.text(m.frame_id, frame, "header.frame_id", "horus::msg::NavPath.frame_id") || !in.count(n, 68, "poses"))
      return false;
    if (n > msg::NavPath::kMaxWaypoints)
      return in.over("poses", std::to_string(n) + " poses; horus::msg::NavPath holds " +
                                  std::to_string(msg::NavPath::kMaxWaypoints));
    m.waypoints = {};
    for (std::size_t i = 0; i < n; ++i) {
      const std::string at = "poses[" + std::to_string(i) + "]";
      std::uint64_t stamp = 0;
      std::string_view pose_frame;
      if (!in.time(stamp, at + ".header.stamp") || !in.string_view(pose_frame, at + ".header.frame_id") ||
          !nav_get_pose(in, m.waypoints[i].pose, at + ".pose"))
        return false;
    }
    m.waypoint_count = static_cast<std::uint16_t>(n);
    m.total_length = m.compute_length();
    m.estimated_time = 0.0;
    m.algorithm = {};
    return true;
  }
};

// sensor_msgs/msg/Joy of one horus joystick event: at most this many axes or buttons are written.
constexpr std::uint32_t kNavJoyElements = 256;

struct JoystickJoy {
  using Horus = msg::JoystickInput;
  static constexpr std::string_view kRos = "sensor_msgs/msg/Joy";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: a JoystickInput is one event, a Joy a whole state: an axis event is axes of element_id + 1 "
      "entries, the last its value and the others 0 (the event does not know them), a button event likewise in "
      "buttons (pressed 1 or 0); hat and connection events and an element_id over 255 give a Joy with no axes and "
      "no buttons; joystick_id, element_name are lost, header.frame_id is the rule's; from ROS 2: only a Joy that "
      "is one event converts (axes or buttons empty, every entry of the other 0 but its last): it is that axis or "
      "button, element_id its index, joystick_id 0, element_name empty; any other Joy state is refused (a state of "
      "several inputs is not one event, and taking one of them would drop the others unseen)";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ms * 1'000'000, ctx.frame_id);
    const bool fits = m.element_id < kNavJoyElements;
    const std::size_t axes = m.is_axis() && fits ? m.element_id + 1 : 0;
    const std::size_t buttons = m.is_button() && fits ? m.element_id + 1 : 0;
    o.count(axes);
    for (std::size_t i = 0; i < axes; ++i) o.num(i == m.element_id ? m.value : 0.0f);
    o.count(buttons);
    for (std::size_t i = 0; i < buttons; ++i) o.num(std::int32_t{i == m.element_id && m.pressed != 0 ? 1 : 0});
  }
  /// Reads axes or buttons: the count n, the last value, and whether an earlier value is not 0.
  template <class N>
  static bool last_of(In& in, std::size_t& n, N& last, bool& earlier, std::string_view field) {
    if (!in.count(n, sizeof(N), field)) return false;
    for (std::size_t i = 0; i < n; ++i) {
      if (!in.num(last, field)) return false;
      if (i + 1 < n && last != N{0}) earlier = true;
    }
    return true;
  }
  static bool get(In& in, Horus& m) {
    std::uint64_t ns = 0;
    std::string_view frame;
    std::size_t axes = 0, buttons = 0;
    float axis = 0.0f;
    std::int32_t button = 0;
    bool earlier = false;
    if (!in.header(ns, frame) || !last_of(in, axes, axis, earlier, "axes") ||
        !last_of(in, buttons, button, earlier, "buttons"))
      return false;
    if ((axes == 0) == (buttons == 0) || earlier)
      return in.over("axes", "a state of " + std::to_string(axes) + " axes and " + std::to_string(buttons) +
                                 " buttons; horus::msg::JoystickInput is one event (one axis or button: the last "
                                 "entry of axes or of buttons, the other entries 0 or absent)");
    m = {};
    m.timestamp_ms = ns / 1'000'000;
    m.element_id = static_cast<std::uint32_t>((axes != 0 ? axes : buttons) - 1);
    m.set_event_type(axes != 0 ? msg::JoystickInput::EVENT_AXIS : msg::JoystickInput::EVENT_BUTTON);
    m.value = axes != 0 ? axis : (button != 0 ? 1.0f : 0.0f);
    m.pressed = static_cast<std::uint8_t>(axes == 0 && button != 0 ? 1 : 0);
    return true;
  }
};

// diagnostic_msgs/msg/DiagnosticStatus.level: OK 0, WARN 1, ERROR 2, STALE 3. horus LEVEL_FATAL
// (and a level horus does not define) is ERROR; ROS 2's STALE (no recent data) is LEVEL_ERROR.
constexpr std::uint8_t kNavRosStale = 3;
std::uint8_t nav_level_to_ros(std::uint8_t level) noexcept {
  return std::min<std::uint8_t>(level, msg::DiagnosticStatus::LEVEL_ERROR);
}
bool nav_level_from_ros(In& in, std::uint8_t& level) {
  if (!in.num(level, "status[0].level")) return false;
  if (level > kNavRosStale)
    return in.over("status[0].level", std::to_string(level) + "; ROS 2 defines OK, WARN, ERROR and STALE (0..3)");
  if (level == kNavRosStale) level = msg::DiagnosticStatus::LEVEL_ERROR;
  return true;
}

/// DiagnosticArray's header and its one status up to its values: the level, name and message.
bool nav_status_head(In& in, std::uint64_t& ns, std::uint8_t& level, std::string_view& name,
                     std::string_view& message, std::string_view horus_type) {
  std::string_view frame, hardware_id;
  std::size_t n = 0;
  if (!in.header(ns, frame) || !in.count(n, 17, "status")) return false;
  if (n != 1)
    return in.over("status", std::to_string(n) + " statuses; " + std::string(horus_type) + " holds exactly 1");
  return nav_level_from_ros(in, level) && in.string_view(name, "status[0].name") &&
         in.string_view(message, "status[0].message") && in.string_view(hardware_id, "status[0].hardware_id");
}
template <class S>
void nav_put_status_head(Out<S>& o, std::uint64_t ns, std::uint8_t level, std::string_view name,
                         std::string_view message, const Context& ctx) {
  o.header(ns, ctx.frame_id);
  o.count(1);
  o.num(nav_level_to_ros(level));
  o.string(name);
  o.string(message);
  o.string(std::string_view{});  // hardware_id
}

struct DiagnosticStatusArray {
  using Horus = msg::DiagnosticStatus;
  static constexpr std::string_view kRos = "diagnostic_msgs/msg/DiagnosticArray";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: one status; LEVEL_FATAL is ERROR; component is its name, code the value of a KeyValue \"code\", "
      "hardware_id is empty, header.frame_id the rule's; from ROS 2: exactly one status (more or none are "
      "refused); STALE is LEVEL_ERROR; hardware_id and every value but a decimal \"code\" are dropped; a name over "
      "31 characters or a message over 127 is refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    nav_put_status_head(o, m.timestamp_ns, m.level, m.component_str(), m.message_str(), ctx);
    std::array<char, 16> code{};
    const auto end = std::to_chars(code.data(), code.data() + code.size(), m.code).ptr;
    o.count(1);
    o.string("code");
    o.string(std::string_view(code.data(), static_cast<std::size_t>(end - code.data())));
  }
  static bool get(In& in, Horus& m) {
    std::string_view name, message;
    std::size_t n = 0;
    if (!nav_status_head(in, m.timestamp_ns, m.level, name, message, "horus::msg::DiagnosticStatus") ||
        !in.text(m.component, name, "status[0].name", "horus::msg::DiagnosticStatus.component") ||
        !in.text(m.message, message, "status[0].message", "horus::msg::DiagnosticStatus.message") ||
        !in.count(n, 8, "status[0].values"))
      return false;
    bool found = false;
    for (std::size_t i = 0; i < n; ++i) {
      std::string_view key, value;
      if (!in.string_view(key, "status[0].values") || !in.string_view(value, "status[0].values")) return false;
      std::uint32_t code = 0;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), code);
      if (!found && key == "code" && ec == std::errc{} && end == value.data() + value.size()) {
        m.code = code;
        found = true;
      }
    }
    return true;
  }
};

struct DiagnosticReportArray {
  using Horus = msg::DiagnosticReport;
  static constexpr std::string_view kRos = "diagnostic_msgs/msg/DiagnosticArray";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: one status; LEVEL_FATAL is ERROR; component is its name, the values its KeyValues (value_type is "
      "lost: ROS 2 values are text), message and hardware_id are empty, header.frame_id the rule's; from ROS 2: "
      "exactly one status; STALE is LEVEL_ERROR; message and hardware_id are dropped, every value_type is "
      "TYPE_STRING; more than 16 values, a key over 31 characters or a value over 63 are refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    nav_put_status_head(o, m.timestamp_ns, m.level, m.component_str(), std::string_view{}, ctx);
    const std::size_t n = m.count();
    o.count(n);
    for (std::size_t i = 0; i < n; ++i) {
      o.string(m.values[i].key);
      o.string(m.values[i].value);
    }
  }
  static bool get(In& in, Horus& m) {
    std::string_view name, message;
    std::size_t n = 0;
    if (!nav_status_head(in, m.timestamp_ns, m.level, name, message, "horus::msg::DiagnosticReport") ||
        !in.text(m.component, name, "status[0].name", "horus::msg::DiagnosticReport.component") ||
        !in.count(n, 8, "status[0].values"))
      return false;
    if (n > msg::DiagnosticReport::kMaxValues)
      return in.over("status[0].values", std::to_string(n) + " values; horus::msg::DiagnosticReport holds " +
                                             std::to_string(msg::DiagnosticReport::kMaxValues));
    m.values = {};
    for (std::size_t i = 0; i < n; ++i) {
      const std::string at = "status[0].values[" + std::to_string(i) + "]";
      std::string_view key, value;
      if (!in.string_view(key, at + ".key") || !in.string_view(value, at + ".value") ||
          !in.text(m.values[i].key, key, at + ".key", "horus::msg::DiagnosticValue.key") ||
          !in.text(m.values[i].value, value, at + ".value", "horus::msg::DiagnosticValue.value"))
        return false;
      m.values[i].value_type = msg::DiagnosticValue::TYPE_STRING;
    }
    m.value_count = static_cast<std::uint8_t>(n);
    return true;
  }
};

struct ClockClock {
  using Horus = msg::Clock;
  static constexpr std::string_view kRos = "rosgraph_msgs/msg/Clock";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: realtime_ns, sim_speed, paused, source and timestamp_ns (clock is clock_ns); from ROS 2: source "
      "is SOURCE_SIM, realtime_ns and timestamp_ns the time of receipt, sim_speed 1 (ROS 2 does not say), paused 0";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context&) {
    o.time(m.clock_ns);
  }
  static bool get(In& in, Horus& m) {
    if (!in.time(m.clock_ns, "clock")) return false;
    m.source = msg::Clock::SOURCE_SIM;
    m.realtime_ns = now_ns();
    m.timestamp_ns = m.realtime_ns;
    m.sim_speed = 1.0;
    m.paused = 0;
    return true;
  }
};

constexpr Conversion kNavigation[] = {
    make_conversion<OdometryOdometry>(),      make_conversion<OccupancyGridOccupancyGrid>(),
    make_conversion<NavPathPath>(),           make_conversion<JoystickJoy>(),
    make_conversion<DiagnosticStatusArray>(), make_conversion<DiagnosticReportArray>(),
    make_conversion<ClockClock>(),
};

}  // namespace

std::span<const Conversion> navigation_conversions() noexcept { return kNavigation; }

}  // namespace horus::ros2::detail
