// The sensor conversions (convert.hpp): IMU, laser scans, rangers, batteries, GNSS fixes, joints.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "cdr_io.hpp"
#include "horus/msg/sensor.hpp"

namespace horus::ros2::detail {
namespace {

/// Reads and drops a sequence of numbers (LaserScan.intensities): its count, then its elements.
template <class N>
bool sensor_skip_numbers(In& in, std::string_view field) {
  std::size_t n = 0;
  if (!in.count(n, sizeof(N), field)) return false;
  if (n == 0) return true;
  if (!in.r.align(sizeof(N)) || n > in.r.remaining() / sizeof(N)) return in.truncated(field);
  in.r.skip(n * sizeof(N));
  return true;
}

struct ImuImu {
  using Horus = msg::Imu;
  static constexpr std::string_view kRos = "sensor_msgs/msg/Imu";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: header.frame_id is the rule's frame_id (an Imu has no frame field); from ROS 2: header.frame_id";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, ctx.frame_id);
    o.run(std::span<const double>(m.orientation));  // x, y, z, w: geometry_msgs/Quaternion's order
    o.run(std::span<const double>(m.orientation_covariance));
    o.run(std::span<const double>(m.angular_velocity));
    o.run(std::span<const double>(m.angular_velocity_covariance));
    o.run(std::span<const double>(m.linear_acceleration));
    o.run(std::span<const double>(m.linear_acceleration_covariance));
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    return in.header(m.timestamp_ns, frame) && in.run(m.orientation.data(), 4, "orientation") &&
           in.run(m.orientation_covariance.data(), 9, "orientation_covariance") &&
           in.run(m.angular_velocity.data(), 3, "angular_velocity") &&
           in.run(m.angular_velocity_covariance.data(), 9, "angular_velocity_covariance") &&
           in.run(m.linear_acceleration.data(), 3, "linear_acceleration") &&
           in.run(m.linear_acceleration_covariance.data(), 9, "linear_acceleration_covariance");
  }
};

/// The beams of a horus scan that go to ROS 2: round((angle_max - angle_min) / angle_increment) + 1
/// for a positive, finite increment and a span that is not negative, at most 360; else all 360.
std::size_t sensor_scan_beams(const msg::LaserScan& m) noexcept {
  constexpr std::size_t kMax = msg::LaserScan::kMaxRanges;
  const double inc = static_cast<double>(m.angle_increment);
  const double steps = (static_cast<double>(m.angle_max) - static_cast<double>(m.angle_min)) / inc;
  if (!(inc > 0.0) || !std::isfinite(inc) || !std::isfinite(steps) || steps < 0.0) return kMax;
  const double beams = std::round(steps) + 1.0;
  return beams >= static_cast<double>(kMax) ? kMax : static_cast<std::size_t>(beams);
}

struct LaserScanLaserScan {
  using Horus = msg::LaserScan;
  static constexpr std::string_view kRos = "sensor_msgs/msg/LaserScan";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: header.frame_id is the rule's frame_id; ranges has round((angle_max - angle_min) / "
      "angle_increment) + 1 beams (at most 360; all 360 when the increment is not a positive number), a range of 0 "
      "(no return) is +inf (REP 117), intensities is empty; from ROS 2: header.frame_id, intensities (read and "
      "dropped); a range that is not finite or outside [range_min, range_max] is 0 (no return); more than 360 beams "
      "are refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, ctx.frame_id);
    o.num(m.angle_min);
    o.num(m.angle_max);
    o.num(m.angle_increment);
    o.num(m.time_increment);
    o.num(m.scan_time);
    o.num(m.range_min);
    o.num(m.range_max);
    const std::size_t n = sensor_scan_beams(m);
    if constexpr (S::kCounting) {  // sizing: the bytes, not the values
      o.sequence(std::span<const float>(m.ranges.data(), n));
    } else {
      std::array<float, msg::LaserScan::kMaxRanges> ranges;  // the first n are written
      for (std::size_t i = 0; i < n; ++i)
        ranges[i] = m.ranges[i] == 0.0f ? std::numeric_limits<float>::infinity() : m.ranges[i];
      o.sequence(std::span<const float>(ranges.data(), n));
    }
    o.count(0);  // intensities
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    if (!in.header(m.timestamp_ns, frame) || !in.num(m.angle_min, "angle_min") || !in.num(m.angle_max, "angle_max") ||
        !in.num(m.angle_increment, "angle_increment") || !in.num(m.time_increment, "time_increment") ||
        !in.num(m.scan_time, "scan_time") || !in.num(m.range_min, "range_min") || !in.num(m.range_max, "range_max"))
      return false;
    std::size_t n = 0;
    m.ranges.fill(0.0f);
    if (!in.sequence(m.ranges.data(), msg::LaserScan::kMaxRanges, n, "ranges", "horus::msg::LaserScan.ranges",
                     "beams"))
      return false;
    for (std::size_t i = 0; i < n; ++i) {
      const float r = m.ranges[i];
      if (!std::isfinite(r) || r < m.range_min || r > m.range_max) m.ranges[i] = 0.0f;
    }
    return sensor_skip_numbers<float>(in, "intensities");
  }
};

struct RangeRange {
  using Horus = msg::Range;
  static constexpr std::string_view kRos = "sensor_msgs/msg/Range";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: header.frame_id is the rule's frame_id, variance is 0 (unknown); from ROS 2: header.frame_id, "
      "variance; a radiation_type other than ULTRASOUND (0) or INFRARED (1) is refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, ctx.frame_id);
    o.num(m.sensor_type);  // ULTRASONIC 0 / INFRARED 1 are ROS 2's ULTRASOUND 0 / INFRARED 1
    o.num(m.field_of_view);
    o.num(m.min_range);
    o.num(m.max_range);
    o.num(m.range);
    o.num(0.0f);  // variance
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    float variance = 0.0f;
    if (!in.header(m.timestamp_ns, frame) || !in.num(m.sensor_type, "radiation_type")) return false;
    if (m.sensor_type > msg::Range::INFRARED)
      return in.over("radiation_type", std::to_string(m.sensor_type) +
                                           "; horus::msg::Range holds ULTRASONIC (0) or INFRARED (1)");
    return in.num(m.field_of_view, "field_of_view") && in.num(m.min_range, "min_range") &&
           in.num(m.max_range, "max_range") && in.num(m.range, "range") && in.num(variance, "variance");
  }
};

// BatteryState.power_supply_status: horus UNKNOWN 0, CHARGING 1, DISCHARGING 2, FULL 3; ROS 2
// UNKNOWN 0, CHARGING 1, DISCHARGING 2, NOT_CHARGING 3, FULL 4.
constexpr std::uint8_t kRosSupplyNotCharging = 3;
constexpr std::uint8_t kRosSupplyFull = 4;
std::uint8_t sensor_supply_to_ros(std::uint8_t s) noexcept {
  if (s == msg::BatteryState::STATUS_FULL) return kRosSupplyFull;
  return s <= msg::BatteryState::STATUS_DISCHARGING ? s : msg::BatteryState::STATUS_UNKNOWN;
}
std::uint8_t sensor_supply_from_ros(std::uint8_t s) noexcept {
  if (s == kRosSupplyFull) return msg::BatteryState::STATUS_FULL;
  return s < kRosSupplyNotCharging ? s : msg::BatteryState::STATUS_UNKNOWN;
}

struct BatteryBatteryState {
  using Horus = msg::BatteryState;
  static constexpr std::string_view kRos = "sensor_msgs/msg/BatteryState";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: header.frame_id is the rule's frame_id; percentage 0..100 is 0..1; design_capacity NaN, "
      "power_supply_health and power_supply_technology UNKNOWN, present true, cell_temperature, location and "
      "serial_number empty; a status horus does not define is UNKNOWN; from ROS 2: header.frame_id, "
      "design_capacity, power_supply_health, power_supply_technology, present, cell_temperature, location, "
      "serial_number; POWER_SUPPLY_STATUS_NOT_CHARGING (and values ROS 2 does not define) are STATUS_UNKNOWN; "
      "more than 16 cell_voltage are refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, ctx.frame_id);
    o.num(m.voltage);
    o.num(m.temperature);
    o.num(m.current);
    o.num(m.charge);
    o.num(m.capacity);
    o.num(std::numeric_limits<float>::quiet_NaN());  // design_capacity
    o.num(m.percentage / 100.0f);
    o.num(sensor_supply_to_ros(m.power_supply_status));
    o.num(std::uint8_t{0});  // power_supply_health: UNKNOWN
    o.num(std::uint8_t{0});  // power_supply_technology: UNKNOWN
    o.boolean(true);         // present
    const std::size_t cells = std::min<std::size_t>(m.cell_count, msg::BatteryState::kMaxCells);
    o.sequence(std::span<const float>(m.cell_voltages.data(), cells));
    o.count(0);  // cell_temperature
    o.string(std::string_view{});  // location
    o.string(std::string_view{});  // serial_number
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    float design_capacity = 0.0f;
    std::uint8_t status = 0, health = 0, technology = 0;
    bool present = false;
    if (!in.header(m.timestamp_ns, frame) || !in.num(m.voltage, "voltage") || !in.num(m.temperature, "temperature") ||
        !in.num(m.current, "current") || !in.num(m.charge, "charge") || !in.num(m.capacity, "capacity") ||
        !in.num(design_capacity, "design_capacity") || !in.num(m.percentage, "percentage") ||
        !in.num(status, "power_supply_status") || !in.num(health, "power_supply_health") ||
        !in.num(technology, "power_supply_technology") || !in.boolean(present, "present"))
      return false;
    m.percentage *= 100.0f;
    m.power_supply_status = sensor_supply_from_ros(status);
    std::size_t cells = 0;
    m.cell_voltages.fill(0.0f);
    if (!in.sequence(m.cell_voltages.data(), msg::BatteryState::kMaxCells, cells, "cell_voltage",
                     "horus::msg::BatteryState.cell_voltages", "cells"))
      return false;
    m.cell_count = static_cast<std::uint8_t>(cells);
    return sensor_skip_numbers<float>(in, "cell_temperature") && in.skip_string("location") &&
           in.skip_string("serial_number");
  }
};

// NavSatStatus.status: ROS 2 STATUS_UNKNOWN -2, NO_FIX -1, FIX 0, SBAS_FIX 1, GBAS_FIX 2; horus
// STATUS_NO_FIX 0, FIX 1, SBAS_FIX 2, GBAS_FIX 3.
constexpr std::int8_t kRosFixUnknown = -2;
constexpr std::int8_t kRosFixGbas = 2;
constexpr std::uint16_t kRosServiceGps = 1;
constexpr std::uint8_t kRosCovarianceUnknown = 0;
constexpr std::uint8_t kRosCovarianceApproximated = 1;

struct NavSatFixNavSatFix {
  using Horus = msg::NavSatFix;
  static constexpr std::string_view kRos = "sensor_msgs/msg/NavSatFix";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: header.frame_id is the rule's frame_id; status NO_FIX..GBAS_FIX is -1..2 (another value is "
      "STATUS_UNKNOWN -2); service is SERVICE_GPS with a fix, else SERVICE_UNKNOWN (horus does not say which "
      "constellation); position_covariance_type is UNKNOWN for an all-zero covariance, else APPROXIMATED; "
      "satellites_visible, hdop, vdop, speed and heading are lost; from ROS 2: header.frame_id, service, "
      "position_covariance_type; STATUS_UNKNOWN is STATUS_NO_FIX, a status outside -2..2 is refused; "
      "satellites_visible, speed and heading are 0, hdop and vdop 99.9 (unknown)";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, ctx.frame_id);
    const bool known = m.status <= msg::NavSatFix::STATUS_GBAS_FIX;
    o.num(known ? static_cast<std::int8_t>(m.status - 1) : kRosFixUnknown);
    o.num(m.has_fix() && known ? kRosServiceGps : std::uint16_t{0});
    o.vector3(m.latitude, m.longitude, m.altitude);
    o.run(std::span<const double>(m.position_covariance));
    const bool zero = std::all_of(m.position_covariance.begin(), m.position_covariance.end(),
                                  [](double v) { return v == 0.0; });
    o.num(zero ? kRosCovarianceUnknown : kRosCovarianceApproximated);
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    std::int8_t status = 0;
    std::uint16_t service = 0;
    std::uint8_t covariance_type = 0;
    if (!in.header(m.timestamp_ns, frame) || !in.num(status, "status.status")) return false;
    if (status < kRosFixUnknown || status > kRosFixGbas)
      return in.over("status.status", std::to_string(status) +
                                          "; horus::msg::NavSatFix holds -2..2 (STATUS_UNKNOWN..STATUS_GBAS_FIX)");
    m.status = status < 0 ? msg::NavSatFix::STATUS_NO_FIX : static_cast<std::uint8_t>(status + 1);
    m.hdop = 99.9f;
    m.vdop = 99.9f;
    return in.num(service, "status.service") && in.vector3(m.latitude, m.longitude, m.altitude, "latitude") &&
           in.run(m.position_covariance.data(), 9, "position_covariance") &&
           in.num(covariance_type, "position_covariance_type");
  }
};

/// One of JointState's position, velocity, effort: empty (zeros) or one value per name.
bool sensor_joint_values(In& in, std::array<double, msg::JointState::kMaxJoints>& out, std::size_t names,
                         std::string_view field) {
  std::size_t n = 0;
  if (!in.count(n, sizeof(double), field)) return false;
  out.fill(0.0);
  if (n == 0) return true;
  if (n != names)
    return in.malformed(field, std::to_string(n) + " values for " + std::to_string(names) +
                                   " names (expected one per name, or none)");
  return in.run(out.data(), n, field);
}

struct JointStateJointState {
  using Horus = msg::JointState;
  static constexpr std::string_view kRos = "sensor_msgs/msg/JointState";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: header.frame_id is the rule's frame_id (a JointState has no frame field); from ROS 2: "
      "header.frame_id; an empty position, velocity or effort is zeros; more than 16 joints or a name over 31 "
      "characters are refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, ctx.frame_id);
    const std::size_t n = m.count();
    o.count(n);
    for (std::size_t i = 0; i < n; ++i) o.string(m.names[i]);
    o.sequence(std::span<const double>(m.positions.data(), n));
    o.sequence(std::span<const double>(m.velocities.data(), n));
    o.sequence(std::span<const double>(m.efforts.data(), n));
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    std::size_t n = 0;
    if (!in.header(m.timestamp_ns, frame) || !in.count(n, 4, "name")) return false;
    if (n > msg::JointState::kMaxJoints)
      return in.over("name", std::to_string(n) + " joints; horus::msg::JointState holds " +
                                 std::to_string(msg::JointState::kMaxJoints));
    m.names = {};
    for (std::size_t i = 0; i < n; ++i) {
      std::string_view name;
      if (!in.string_view(name, "name")) return false;
      if (!set_fixed_str(m.names[i], name))
        return in.text(m.names[i], name, "name[" + std::to_string(i) + "]", "horus::msg::JointState.names");
    }
    m.joint_count = static_cast<std::uint8_t>(n);
    return sensor_joint_values(in, m.positions, n, "position") &&
           sensor_joint_values(in, m.velocities, n, "velocity") && sensor_joint_values(in, m.efforts, n, "effort");
  }
};

constexpr Conversion kSensor[] = {
    make_conversion<ImuImu>(),           make_conversion<LaserScanLaserScan>(),
    make_conversion<RangeRange>(),       make_conversion<BatteryBatteryState>(),
    make_conversion<NavSatFixNavSatFix>(), make_conversion<JointStateJointState>(),
};

}  // namespace

std::span<const Conversion> sensor_conversions() noexcept { return kSensor; }

}  // namespace horus::ros2::detail
