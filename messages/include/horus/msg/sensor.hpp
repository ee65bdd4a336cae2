// Sensor messages: Imu, LaserScan, Odometry, JointState, Range, BatteryState,
// NavSatFix.
//
// Fixed-size (trivially copyable) like every standard message: text fields are
// NUL-terminated std::array<char, 32>, written through set_fixed_str() so a
// name that does not fit is refused rather than cut. Units as in geometry.hpp.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>

#include "horus/fixed_string.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

namespace detail {
template <std::size_t N>
bool all_finite(const std::array<double, N>& a) noexcept {
  return std::all_of(a.begin(), a.end(), [](double v) { return std::isfinite(v); });
}
}  // namespace detail

// ---------------------------------------------------------------------------
/// Inertial measurement. As in ROS, orientation_covariance[0] == -1 means the
/// sensor gives no orientation (has_orientation() is then false; so does any
/// other negative or NaN first element).
struct Imu {
  std::array<double, 4> orientation{};                     ///< quaternion [x, y, z, w]
  std::array<double, 9> orientation_covariance{};          ///< 3x3, row-major
  std::array<double, 3> angular_velocity{};                ///< rad/s
  std::array<double, 9> angular_velocity_covariance{};     ///< 3x3, row-major
  std::array<double, 3> linear_acceleration{};             ///< m/s^2
  std::array<double, 9> linear_acceleration_covariance{};  ///< 3x3, row-major
  std::uint64_t timestamp_ns{};

  /// The spec's Imu::new(): identity orientation, everything else zero.
  static constexpr Imu make() noexcept {
    Imu imu{};
    imu.orientation = {0.0, 0.0, 0.0, 1.0};
    return imu;
  }

  /// Sets orientation from roll, pitch, yaw in radians (ZYX, see geometry.hpp).
  void set_orientation_from_euler(double roll, double pitch, double yaw) noexcept {
    const Quaternion q = Quaternion::from_euler(roll, pitch, yaw);
    orientation = {q.x, q.y, q.z, q.w};
  }

  /// True when orientation_covariance[0] >= 0 (as HORUS). The ROS sentinel -1
  /// means "no orientation"; so does any other negative value and NaN (a
  /// variance is never negative, and NaN compares false).
  constexpr bool has_orientation() const noexcept { return orientation_covariance[0] >= 0.0; }

  /// Every number (data and covariances) finite.
  bool is_valid() const noexcept {
    return detail::all_finite(orientation) && detail::all_finite(orientation_covariance) &&
           detail::all_finite(angular_velocity) && detail::all_finite(angular_velocity_covariance) &&
           detail::all_finite(linear_acceleration) && detail::all_finite(linear_acceleration_covariance);
  }

  friend constexpr bool operator==(const Imu&, const Imu&) = default;
};
HORUS_REFLECT(Imu, orientation, orientation_covariance, angular_velocity, angular_velocity_covariance,
              linear_acceleration, linear_acceleration_covariance, timestamp_ns)

// ---------------------------------------------------------------------------
/// A planar lidar scan of up to 360 beams. ranges[i] is the distance in metres
/// along angle_at(i); 0 (or NaN, inf, or a value outside [range_min, range_max])
/// means no return.
struct LaserScan {
  static constexpr std::size_t kMaxRanges = 360;

  std::array<float, kMaxRanges> ranges{};  ///< m, 0 = invalid
  float angle_min{};                       ///< rad, angle of ranges[0]
  float angle_max{};                       ///< rad
  float range_min{};                       ///< m
  float range_max{};                       ///< m
  float angle_increment{};                 ///< rad between beams
  float time_increment{};                  ///< s between beams
  float scan_time{};                       ///< s for a whole scan
  std::uint64_t timestamp_ns{};

  /// The spec's LaserScan::new() with HORUS's defaults: a full turn [-pi, pi]
  /// at 1 degree steps, valid ranges 0.1 m to 30 m, scan_time 0.1 s (10 Hz),
  /// time_increment 0, all ranges 0 (no return); the timestamp is left 0.
  static constexpr LaserScan make() noexcept {
    LaserScan s{};
    s.angle_min = -std::numbers::pi_v<float>;
    s.angle_max = std::numbers::pi_v<float>;
    s.angle_increment = 2.0f * std::numbers::pi_v<float> / static_cast<float>(kMaxRanges);
    s.range_min = 0.1f;
    s.range_max = 30.0f;
    s.scan_time = 0.1f;
    return s;
  }

  /// The angle of beam i in radians: angle_min + i * angle_increment.
  constexpr float angle_at(std::size_t i) const noexcept {
    return angle_min + static_cast<float>(i) * angle_increment;
  }

  /// True when i is a beam index and ranges[i] is a finite, non-zero distance
  /// within [range_min, range_max].
  bool is_range_valid(std::size_t i) const noexcept {
    if (i >= ranges.size()) return false;
    const float r = ranges[i];
    return std::isfinite(r) && r > 0.0f && r >= range_min && r <= range_max;
  }

  /// Number of valid ranges.
  std::size_t valid_count() const noexcept {
    std::size_t n = 0;
    for (std::size_t i = 0; i < ranges.size(); ++i)
      if (is_range_valid(i)) ++n;
    return n;
  }

  /// The smallest valid range in metres, or nullopt when no beam has a return.
  std::optional<float> min_range() const noexcept {
    std::optional<float> best;
    for (std::size_t i = 0; i < ranges.size(); ++i)
      if (is_range_valid(i) && (!best || ranges[i] < *best)) best = ranges[i];
    return best;
  }

  /// "LaserScan(360 ranges, 120 valid, min 0.45 m, fov 6.28 rad)".
  std::string log_summary() const;

  friend constexpr bool operator==(const LaserScan&, const LaserScan&) = default;
};
HORUS_REFLECT(LaserScan, ranges, angle_min, angle_max, range_min, range_max, angle_increment, time_increment,
              scan_time, timestamp_ns)

// ---------------------------------------------------------------------------
/// Pose and velocity of child_frame_id (e.g. "base_link") in frame_id (e.g. "odom").
struct Odometry {
  Pose2D pose{};
  Twist twist{};
  std::array<double, 36> pose_covariance{};   ///< 6x6, row-major (x, y, z, roll, pitch, yaw)
  std::array<double, 36> twist_covariance{};  ///< 6x6, row-major
  std::array<char, 32> frame_id{};            ///< NUL-terminated, at most 31 characters
  std::array<char, 32> child_frame_id{};      ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// The spec's Odometry::new(): pose at the origin, zero twist, zero
  /// covariances, no frame names; the timestamp is left 0 (HORUS reads the
  /// clock; stamp it yourself). Equal to Odometry{}.
  static constexpr Odometry make() noexcept {
    Odometry o{};
    o.pose = Pose2D::origin();
    o.twist = Twist::stop();
    return o;
  }

  /// Sets both frame names. Returns false and changes nothing when either
  /// does not fit (at most 31 characters, no NUL).
  bool set_frames(std::string_view frame, std::string_view child_frame) noexcept {
    if (!fixed_str_fits<32>(frame) || !fixed_str_fits<32>(child_frame)) return false;
    set_fixed_str(frame_id, frame);
    set_fixed_str(child_frame_id, child_frame);
    return true;
  }
  std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }
  std::string_view child_frame_id_str() const noexcept { return fixed_str_view(child_frame_id); }

  /// Replaces pose and twist; timestamp_ns is left for the caller to set.
  void update(const Pose2D& new_pose, const Twist& new_twist) noexcept {
    pose = new_pose;
    twist = new_twist;
  }
  /// Replaces pose and twist and stamps the message.
  void update(const Pose2D& new_pose, const Twist& new_twist, std::uint64_t stamp_ns) noexcept {
    update(new_pose, new_twist);
    timestamp_ns = stamp_ns;
  }

  /// Pose (x, y, theta) and twist (all six components) finite, and every
  /// entry of both covariance matrices finite. NaN or an infinity anywhere
  /// there gives false. HORUS checks only pose and twist; the covariances are
  /// checked here too. Timestamps and frame names are not consulted.
  bool is_valid() const noexcept {
    return pose.is_valid() && twist.is_valid() && detail::all_finite(pose_covariance) &&
           detail::all_finite(twist_covariance);
  }

  /// "Odometry(odom -> base_link, x 1.00 m, y 2.00 m, theta 0.50 rad, v 0.50 m/s, w 0.20 rad/s)".
  std::string log_summary() const;

  friend constexpr bool operator==(const Odometry&, const Odometry&) = default;
};
HORUS_REFLECT(Odometry, pose, twist, pose_covariance, twist_covariance, frame_id, child_frame_id, timestamp_ns)

// ---------------------------------------------------------------------------
/// Feedback of up to 16 named joints. Entries [0, joint_count) are in use.
/// Positions are rad (revolute) or m (prismatic), velocities rad/s or m/s,
/// efforts N*m or N.
struct JointState {
  static constexpr std::size_t kMaxJoints = 16;

  std::array<std::array<char, 32>, kMaxJoints> names{};
  std::uint8_t joint_count{};
  std::array<double, kMaxJoints> positions{};
  std::array<double, kMaxJoints> velocities{};
  std::array<double, kMaxJoints> efforts{};
  std::uint64_t timestamp_ns{};

  /// joint_count, clamped to kMaxJoints (a received message may hold any byte).
  constexpr std::size_t count() const noexcept { return std::min<std::size_t>(joint_count, kMaxJoints); }

  /// Appends a joint. Returns false, changing nothing, when the message is full,
  /// the name is empty, does not fit (31 characters at most) or is already used.
  bool add_joint(std::string_view name, double position, double velocity = 0.0, double effort = 0.0) noexcept {
    const std::size_t i = count();
    if (i >= kMaxJoints || name.empty() || index_of(name)) return false;
    if (!set_fixed_str(names[i], name)) return false;
    positions[i] = position;
    velocities[i] = velocity;
    efforts[i] = effort;
    joint_count = static_cast<std::uint8_t>(i + 1);
    return true;
  }

  /// The name of joint i, or "" when i >= joint_count.
  std::string_view name_at(std::size_t i) const noexcept {
    return i < count() ? fixed_str_view(names[i]) : std::string_view{};
  }

  /// The index of the joint called name, if any.
  std::optional<std::size_t> index_of(std::string_view name) const noexcept {
    for (std::size_t i = 0; i < count(); ++i)
      if (fixed_str_view(names[i]) == name) return i;
    return std::nullopt;
  }

  /// The position of the joint called name, if any.
  std::optional<double> position_of(std::string_view name) const noexcept {
    if (const auto i = index_of(name)) return positions[*i];
    return std::nullopt;
  }

  /// "JointState(6 joints, positions in rad or m: shoulder=0.5, elbow=-1.2, wrist=0, +3 more)".
  /// Lists as many joints as fit in about 170 characters, then "+N more": the
  /// line always stays under 200 characters.
  std::string log_summary() const;

  friend constexpr bool operator==(const JointState&, const JointState&) = default;
};
HORUS_REFLECT(JointState, names, joint_count, positions, velocities, efforts, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<Imu>, "Imu must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<LaserScan>, "LaserScan must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Odometry>, "Odometry must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<JointState>, "JointState must be trivially copyable and standard layout");

// ---------------------------------------------------------------------------
/// A single distance reading from an ultrasonic or infrared ranger.
struct Range {
  static constexpr std::uint8_t ULTRASONIC = 0;
  static constexpr std::uint8_t INFRARED = 1;

  std::uint8_t sensor_type{};  ///< ULTRASONIC or INFRARED
  float field_of_view{};       ///< rad, full cone angle
  float min_range{};           ///< m
  float max_range{};           ///< m
  float range{};               ///< m
  std::uint64_t timestamp_ns{};

  /// The spec's Range::new(sensor_type, range) with HORUS's defaults: field of
  /// view 0.1 rad (about 6 degrees), limits 0.02 m to 4 m; the timestamp is left 0.
  static constexpr Range make(std::uint8_t type, float range_m) noexcept {
    return Range{type, 0.1f, 0.02f, 4.0f, range_m, 0};
  }

  /// True when range is finite and within [min_range, max_range], both limits
  /// included. NaN in the reading or in either limit gives false.
  bool is_valid() const noexcept { return std::isfinite(range) && range >= min_range && range <= max_range; }

  friend constexpr bool operator==(const Range&, const Range&) = default;
};
HORUS_REFLECT(Range, sensor_type, field_of_view, min_range, max_range, range, timestamp_ns)

// ---------------------------------------------------------------------------
/// Battery status. NaN in charge or capacity means "not measured" (as in ROS
/// and HORUS); make() starts them as NaN, so two make() results do not compare
/// equal with ==.
struct BatteryState {
  static constexpr std::uint8_t STATUS_UNKNOWN = 0;
  static constexpr std::uint8_t STATUS_CHARGING = 1;
  static constexpr std::uint8_t STATUS_DISCHARGING = 2;
  static constexpr std::uint8_t STATUS_FULL = 3;
  static constexpr std::size_t kMaxCells = 16;
  /// is_critical() threshold, in percent.
  static constexpr float kCriticalPercent = 10.0f;

  float voltage{};                               ///< V
  float current{};                               ///< A, negative = discharging
  float charge{};                                ///< Ah remaining, NaN = unknown
  float capacity{};                              ///< Ah when full, NaN = unknown
  float percentage{};                            ///< 0 to 100
  std::uint8_t power_supply_status{};            ///< STATUS_UNKNOWN, _CHARGING, _DISCHARGING or _FULL
  float temperature{};                           ///< degrees Celsius
  std::array<float, kMaxCells> cell_voltages{};  ///< V, entries [0, cell_count) in use
  std::uint8_t cell_count{};
  std::uint64_t timestamp_ns{};

  /// The spec's BatteryState::new(voltage, percentage) with HORUS's defaults:
  /// current 0, charge and capacity NaN (unknown), STATUS_UNKNOWN, temperature
  /// 25 degrees C, no cells; the timestamp is left 0.
  static constexpr BatteryState make(float voltage_v, float percent) noexcept {
    BatteryState b{};
    b.voltage = voltage_v;
    b.charge = std::numeric_limits<float>::quiet_NaN();
    b.capacity = std::numeric_limits<float>::quiet_NaN();
    b.percentage = percent;
    b.power_supply_status = STATUS_UNKNOWN;
    b.temperature = 25.0f;
    return b;
  }

  /// True when percentage is strictly below threshold_percent (so exactly at the
  /// threshold is not low). A NaN percentage or threshold gives false.
  constexpr bool is_low(float threshold_percent) const noexcept { return percentage < threshold_percent; }

  /// True below 10 % (strictly: exactly 10 % is not critical). NaN gives false.
  constexpr bool is_critical() const noexcept { return percentage < kCriticalPercent; }

  /// Seconds until the remaining charge is used up at the present current:
  /// charge (Ah) / -current (A) * 3600. Only while discharging, which the sign
  /// of current decides (power_supply_status is not consulted, as in HORUS):
  /// nullopt when current is >= 0 (charging or idle), NaN or infinite, or when
  /// charge is unknown (NaN), infinite or negative. A charge of 0 gives 0 s.
  std::optional<double> time_remaining() const noexcept {
    if (!(current < 0.0f) || !std::isfinite(current)) return std::nullopt;
    if (!std::isfinite(charge) || charge < 0.0f) return std::nullopt;
    return static_cast<double>(charge) / -static_cast<double>(current) * 3600.0;
  }

  /// "BatteryState(12.60 V, 75.0 %, -2.50 A, discharging, 28.5 degC, 3 cells)".
  std::string log_summary() const;

  friend constexpr bool operator==(const BatteryState&, const BatteryState&) = default;
};
HORUS_REFLECT(BatteryState, voltage, current, charge, capacity, percentage, power_supply_status, temperature,
              cell_voltages, cell_count, timestamp_ns)

// ---------------------------------------------------------------------------
/// A GNSS (GPS, GLONASS, Galileo ...) position fix. Latitude and longitude in
/// degrees (north and east positive), altitude in metres above the WGS84
/// ellipsoid.
struct NavSatFix {
  static constexpr std::uint8_t STATUS_NO_FIX = 0;
  static constexpr std::uint8_t STATUS_FIX = 1;
  static constexpr std::uint8_t STATUS_SBAS_FIX = 2;  ///< satellite-based augmentation
  static constexpr std::uint8_t STATUS_GBAS_FIX = 3;  ///< ground-based augmentation
  /// Mean Earth radius used by distance_to(), in metres.
  static constexpr double kEarthRadiusM = 6'371'000.0;

  double latitude{};                            ///< degrees, [-90, 90]
  double longitude{};                           ///< degrees, [-180, 180]
  double altitude{};                            ///< m above the WGS84 ellipsoid
  std::array<double, 9> position_covariance{};  ///< 3x3, row-major, m^2 (latitude, longitude, altitude order)
  std::uint8_t status{};                        ///< STATUS_NO_FIX ... STATUS_GBAS_FIX
  std::uint16_t satellites_visible{};
  float hdop{};     ///< horizontal dilution of precision
  float vdop{};     ///< vertical dilution of precision
  float speed{};    ///< m/s over ground
  float heading{};  ///< rad (the spec's unit; HORUS Rust documents degrees)
  std::uint64_t timestamp_ns{};

  /// The spec's NavSatFix::new(): no fix, position 0, hdop and vdop 99.9
  /// ("unknown precision", as HORUS); the timestamp is left 0.
  static constexpr NavSatFix make() noexcept {
    NavSatFix f{};
    f.hdop = 99.9f;
    f.vdop = 99.9f;
    return f;
  }
  /// A fix (STATUS_FIX) at the given position; otherwise as make().
  static constexpr NavSatFix from_coordinates(double lat_deg, double lon_deg, double alt_m) noexcept {
    NavSatFix f = make();
    f.latitude = lat_deg;
    f.longitude = lon_deg;
    f.altitude = alt_m;
    f.status = STATUS_FIX;
    return f;
  }

  /// True for STATUS_FIX and better (any status >= STATUS_FIX, as HORUS).
  constexpr bool has_fix() const noexcept { return status >= STATUS_FIX; }

  /// Latitude within [-90, 90], longitude within [-180, 180] (limits
  /// included) and altitude finite; NaN anywhere gives false.
  bool is_valid() const noexcept {
    return std::isfinite(latitude) && std::isfinite(longitude) && std::isfinite(altitude) && latitude >= -90.0 &&
           latitude <= 90.0 && longitude >= -180.0 && longitude <= 180.0;
  }

  /// A rough horizontal accuracy in metres: hdop * 5 m (as HORUS).
  constexpr float horizontal_accuracy() const noexcept { return hdop * 5.0f; }

  /// Great-circle (haversine) distance in metres to other, on a sphere of
  /// radius kEarthRadiusM; altitude is ignored. NaN coordinates give NaN.
  double distance_to(const NavSatFix& other) const noexcept {
    constexpr double deg = std::numbers::pi / 180.0;
    const double lat1 = latitude * deg;
    const double lat2 = other.latitude * deg;
    const double dlat = (other.latitude - latitude) * deg;
    const double dlon = (other.longitude - longitude) * deg;
    const double s_lat = std::sin(dlat / 2.0);
    const double s_lon = std::sin(dlon / 2.0);
    double a = s_lat * s_lat + std::cos(lat1) * std::cos(lat2) * s_lon * s_lon;
    if (std::isnan(a)) return a;
    a = std::clamp(a, 0.0, 1.0);  // rounding can push it just outside [0, 1]
    return kEarthRadiusM * 2.0 * std::atan2(std::sqrt(a), std::sqrt(1.0 - a));
  }

  /// "NavSatFix(lat 47.397742 deg, lon 8.545594 deg, alt 488.0 m, 9 sats, fix, hdop 0.9)".
  std::string log_summary() const;

  friend constexpr bool operator==(const NavSatFix&, const NavSatFix&) = default;
};
HORUS_REFLECT(NavSatFix, latitude, longitude, altitude, position_covariance, status, satellites_visible, hdop, vdop,
              speed, heading, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<Range>, "Range must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<BatteryState>,
              "BatteryState must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<NavSatFix>, "NavSatFix must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(LaserScan, Imu, Odometry, Range, BatteryState, NavSatFix, JointState)

}  // namespace horus::msg

HORUS_API_END
