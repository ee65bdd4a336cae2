// Control messages: JointCommand, MotorCommand, DifferentialDriveCommand,
// ServoCommand, PidConfig, TrajectoryPoint.
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

// ---------------------------------------------------------------------------
/// Targets for up to 16 named joints. Entries [0, joint_count) are in use;
/// modes[i] says which of positions / velocities / efforts joint i follows (the
/// other two may carry limits). Units as JointState: rad or m, rad/s or m/s,
/// N*m or N.
struct JointCommand {
  static constexpr std::size_t kMaxJoints = 16;
  static constexpr std::uint8_t MODE_POSITION = 0;
  static constexpr std::uint8_t MODE_VELOCITY = 1;
  static constexpr std::uint8_t MODE_EFFORT = 2;

  std::array<std::array<char, 32>, kMaxJoints> joint_names{};
  std::uint8_t joint_count{};
  std::array<double, kMaxJoints> positions{};
  std::array<double, kMaxJoints> velocities{};
  std::array<double, kMaxJoints> efforts{};
  std::array<std::uint8_t, kMaxJoints> modes{};
  std::uint64_t timestamp_ns{};

  /// joint_count, clamped to kMaxJoints (a received message may hold any byte).
  constexpr std::size_t count() const noexcept { return std::min<std::size_t>(joint_count, kMaxJoints); }

  /// Position target (MODE_POSITION) for the joint called name. A joint already
  /// in the command is updated (its mode becomes MODE_POSITION); a new one is
  /// appended. Returns false, changing nothing, when a new joint does not fit:
  /// the command is full, or the name is empty or longer than 31 characters.
  bool add_position(std::string_view name, double position) noexcept {
    return set_target(name, MODE_POSITION, [&](std::size_t i) { positions[i] = position; });
  }
  /// Velocity target (MODE_VELOCITY); same rules as add_position.
  bool add_velocity(std::string_view name, double velocity) noexcept {
    return set_target(name, MODE_VELOCITY, [&](std::size_t i) { velocities[i] = velocity; });
  }
  /// Effort target (MODE_EFFORT); same rules as add_position.
  bool add_effort(std::string_view name, double effort) noexcept {
    return set_target(name, MODE_EFFORT, [&](std::size_t i) { efforts[i] = effort; });
  }

  /// The name of joint i, or "" when i >= joint_count.
  std::string_view name_at(std::size_t i) const noexcept {
    return i < count() ? fixed_str_view(joint_names[i]) : std::string_view{};
  }
  /// The index of the joint called name, if any.
  std::optional<std::size_t> index_of(std::string_view name) const noexcept {
    for (std::size_t i = 0; i < count(); ++i)
      if (fixed_str_view(joint_names[i]) == name) return i;
    return std::nullopt;
  }

  /// "JointCommand(3 joints: shoulder pos 1 rad|m, elbow vel 0.5 rad/s|m/s, wrist effort 2 Nm|N)".
  /// Lists as many joints as fit in about 170 characters, then "+N more": the
  /// line always stays under 200 characters.
  std::string log_summary() const;

  friend constexpr bool operator==(const JointCommand&, const JointCommand&) = default;

 private:
  template <class Set>
  bool set_target(std::string_view name, std::uint8_t mode, Set set) noexcept {
    std::size_t i = 0;
    if (const auto found = index_of(name)) {
      i = *found;
    } else {
      i = count();
      if (i >= kMaxJoints || name.empty() || !set_fixed_str(joint_names[i], name)) return false;
      joint_count = static_cast<std::uint8_t>(i + 1);
    }
    set(i);
    modes[i] = mode;
    return true;
  }
};
HORUS_REFLECT(JointCommand, joint_names, joint_count, positions, velocities, efforts, modes, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<JointCommand>,
              "JointCommand must be trivially copyable and standard layout");

// ---------------------------------------------------------------------------
/// Direct command to one motor. The spec types mode as f32; it holds one of the
/// MODE_ values (0 to 3). target is in the unit of the mode: rad/s or m/s
/// (velocity), rad or m (position), N*m (torque), V (voltage). A limit of
/// +infinity means "no limit" (note that JSON has no infinity: it travels as
/// null and is read back as NaN, which is_valid() rejects).
struct MotorCommand {
  static constexpr std::uint8_t MODE_VELOCITY = 0;
  static constexpr std::uint8_t MODE_POSITION = 1;
  static constexpr std::uint8_t MODE_TORQUE = 2;
  static constexpr std::uint8_t MODE_VOLTAGE = 3;

  std::uint32_t motor_id{};
  float mode{};              ///< one of MODE_VELOCITY, MODE_POSITION, MODE_TORQUE, MODE_VOLTAGE
  float target{};            ///< in the unit of the mode
  float max_velocity{};      ///< rad/s or m/s, +inf = no limit
  float max_acceleration{};  ///< rad/s^2 or m/s^2, +inf = no limit
  float feed_forward{};      ///< added to the controller output, in the unit of the mode
  std::uint8_t enable{};     ///< 1 = drive, 0 = brake or coast (driver's choice)
  std::uint64_t timestamp_ns{};

  /// Spin at velocity (rad/s or m/s), enabled, no limits; the timestamp is left 0.
  static constexpr MotorCommand velocity(std::uint32_t id, float velocity_target) noexcept {
    return MotorCommand{id, MODE_VELOCITY, velocity_target, kNoLimit, kNoLimit, 0.0f, 1, 0};
  }
  /// Move to position (rad or m) at up to max_velocity_limit, enabled, no acceleration limit.
  static constexpr MotorCommand position(std::uint32_t id, float position_target, float max_velocity_limit) noexcept {
    return MotorCommand{id, MODE_POSITION, position_target, max_velocity_limit, kNoLimit, 0.0f, 1, 0};
  }
  /// Velocity 0 and disabled (enable = 0), no limits.
  static constexpr MotorCommand stop(std::uint32_t id) noexcept {
    return MotorCommand{id, MODE_VELOCITY, 0.0f, kNoLimit, kNoLimit, 0.0f, 0, 0};
  }

  /// True when mode is one of the four MODE_ values, target and feed_forward
  /// are finite, and both limits are >= 0 (+infinity allowed, NaN not).
  /// HORUS Rust also rejects infinite limits, which its own velocity() sets; here
  /// +infinity is the documented "no limit" and is valid.
  bool is_valid() const noexcept {
    const bool known_mode =
        mode == MODE_VELOCITY || mode == MODE_POSITION || mode == MODE_TORQUE || mode == MODE_VOLTAGE;
    return known_mode && std::isfinite(target) && std::isfinite(feed_forward) && max_velocity >= 0.0f &&
           max_acceleration >= 0.0f;
  }

  friend constexpr bool operator==(const MotorCommand&, const MotorCommand&) = default;

 private:
  static constexpr float kNoLimit = std::numeric_limits<float>::infinity();
};
HORUS_REFLECT(MotorCommand, motor_id, mode, target, max_velocity, max_acceleration, feed_forward, enable, timestamp_ns)

// ---------------------------------------------------------------------------
/// Wheel speeds for a two-wheeled differential drive, in m/s at the wheel rim
/// (the spec's unit; HORUS Rust uses rad/s and takes a wheel radius).
struct DifferentialDriveCommand {
  float left_velocity{};     ///< m/s
  float right_velocity{};    ///< m/s
  float max_acceleration{};  ///< m/s^2, +inf = no limit
  std::uint8_t enable{};     ///< 1 = drive, 0 = motors off
  std::uint64_t timestamp_ns{};

  /// The spec's DifferentialDriveCommand::new(left, right): enabled, no
  /// acceleration limit; the timestamp is left 0.
  static constexpr DifferentialDriveCommand make(float left_mps, float right_mps) noexcept {
    return DifferentialDriveCommand{left_mps, right_mps, std::numeric_limits<float>::infinity(), 1, 0};
  }
  /// Both wheels 0 and disabled (enable = 0), no acceleration limit.
  static constexpr DifferentialDriveCommand stop() noexcept {
    return DifferentialDriveCommand{0.0f, 0.0f, std::numeric_limits<float>::infinity(), 0, 0};
  }

  /// Wheel speeds for a body velocity: forward linear_mps (m/s) and yaw rate
  /// angular_radps (rad/s, counter-clockwise positive), with wheel_base_m the
  /// distance between the wheels: left = v - w * b / 2, right = v + w * b / 2.
  /// Enabled, no acceleration limit. A wheel base of 0 ignores the yaw rate
  /// (both wheels get v); NaN or infinite inputs give non-finite wheel speeds,
  /// which is_valid() rejects.
  static constexpr DifferentialDriveCommand from_twist(double linear_mps, double angular_radps,
                                                       double wheel_base_m) noexcept {
    const double half_diff = angular_radps * wheel_base_m / 2.0;
    return make(static_cast<float>(linear_mps - half_diff), static_cast<float>(linear_mps + half_diff));
  }
  /// The planar part of twist (linear[0], angular[2]); see the overload above.
  static constexpr DifferentialDriveCommand from_twist(const Twist& twist, double wheel_base_m) noexcept {
    return from_twist(twist.linear[0], twist.angular[2], wheel_base_m);
  }

  /// Both wheel speeds finite and max_acceleration >= 0 (+infinity allowed, NaN not).
  bool is_valid() const noexcept {
    return std::isfinite(left_velocity) && std::isfinite(right_velocity) && max_acceleration >= 0.0f;
  }

  friend constexpr bool operator==(const DifferentialDriveCommand&, const DifferentialDriveCommand&) = default;
};
HORUS_REFLECT(DifferentialDriveCommand, left_velocity, right_velocity, max_acceleration, enable, timestamp_ns)

// ---------------------------------------------------------------------------
/// Target for one position-controlled servo. speed is a fraction in [0, 1] of
/// the servo's range of speeds where, as in HORUS, 0 means "as fast as it can".
struct ServoCommand {
  std::uint32_t servo_id{};
  float position{};       ///< rad
  float speed{};          ///< [0, 1], 0 = maximum speed
  std::uint8_t enable{};  ///< 1 = torque on, 0 = limp
  std::uint64_t timestamp_ns{};

  /// The spec's ServoCommand::new(id, position): speed 0.5, enabled; the timestamp is left 0.
  static constexpr ServoCommand make(std::uint32_t id, float position_rad) noexcept {
    return ServoCommand{id, position_rad, 0.5f, 1, 0};
  }
  /// As make(), with speed clamped into [0, 1] (a NaN speed stays NaN, which is_valid() rejects).
  static constexpr ServoCommand with_speed(std::uint32_t id, float position_rad, float speed_fraction) noexcept {
    return ServoCommand{id, position_rad, std::clamp(speed_fraction, 0.0f, 1.0f), 1, 0};
  }
  /// Torque off (enable = 0), position and speed 0.
  static constexpr ServoCommand disable(std::uint32_t id) noexcept { return ServoCommand{id, 0.0f, 0.0f, 0, 0}; }
  /// As make(), with the position given in degrees.
  static constexpr ServoCommand from_degrees(std::uint32_t id, float position_deg) noexcept {
    return make(id, position_deg * (std::numbers::pi_v<float> / 180.0f));
  }

  /// position finite and speed within [0, 1] (limits included; NaN gives false).
  bool is_valid() const noexcept { return std::isfinite(position) && speed >= 0.0f && speed <= 1.0f; }

  friend constexpr bool operator==(const ServoCommand&, const ServoCommand&) = default;
};
HORUS_REFLECT(ServoCommand, servo_id, position, speed, enable, timestamp_ns)

// ---------------------------------------------------------------------------
/// Gains and limits of one PID controller. A limit of +infinity means "no
/// limit" (JSON carries it as null, read back as NaN: see MotorCommand).
struct PidConfig {
  std::uint32_t controller_id{};
  double kp{};                 ///< proportional gain
  double ki{};                 ///< integral gain, per second
  double kd{};                 ///< derivative gain, seconds
  double integral_limit{};     ///< bound on |integral term|, +inf = none
  double output_limit{};       ///< bound on |output|, +inf = none
  std::uint8_t anti_windup{};  ///< 1 = stop integrating while the output saturates
  std::uint64_t timestamp_ns{};

  /// The spec's PidConfig::new(kp, ki, kd): controller 0, no limits, anti-windup
  /// on; the timestamp is left 0.
  static constexpr PidConfig make(double p, double i, double d) noexcept {
    constexpr double inf = std::numeric_limits<double>::infinity();
    return PidConfig{0, p, i, d, inf, inf, 1, 0};
  }
  static constexpr PidConfig proportional(double p) noexcept { return make(p, 0.0, 0.0); }
  static constexpr PidConfig pi(double p, double i) noexcept { return make(p, i, 0.0); }
  static constexpr PidConfig pd(double p, double d) noexcept { return make(p, 0.0, d); }

  /// A copy with both limits replaced.
  [[nodiscard]] constexpr PidConfig with_limits(double integral, double output) const noexcept {
    PidConfig c = *this;
    c.integral_limit = integral;
    c.output_limit = output;
    return c;
  }

  /// Gains finite and >= 0; limits >= 0 (+infinity allowed, NaN not). HORUS
  /// Rust also rejects infinite limits, which its own new() sets.
  bool is_valid() const noexcept {
    return std::isfinite(kp) && std::isfinite(ki) && std::isfinite(kd) && kp >= 0.0 && ki >= 0.0 && kd >= 0.0 &&
           integral_limit >= 0.0 && output_limit >= 0.0;
  }

  friend constexpr bool operator==(const PidConfig&, const PidConfig&) = default;
};
HORUS_REFLECT(PidConfig, controller_id, kp, ki, kd, integral_limit, output_limit, anti_windup, timestamp_ns)

// ---------------------------------------------------------------------------
/// One timed point of a trajectory: position (m), velocity (m/s), acceleration
/// (m/s^2), orientation quaternion [x, y, z, w], angular velocity (rad/s).
/// `TrajectoryPoint{}` has a zero quaternion; the factories set identity.
struct TrajectoryPoint {
  std::array<double, 3> position{};
  std::array<double, 3> velocity{};
  std::array<double, 3> acceleration{};
  std::array<double, 4> orientation{};
  std::array<double, 3> angular_velocity{};
  double time_from_start{};  ///< s since the trajectory starts

  /// A planar point at (x, y, 0) moving at (vx, vy, 0), identity orientation,
  /// reached time_s after the start.
  static constexpr TrajectoryPoint new_2d(double x, double y, double vx, double vy, double time_s) noexcept {
    return TrajectoryPoint{{x, y, 0.0}, {vx, vy, 0.0}, {}, {0.0, 0.0, 0.0, 1.0}, {}, time_s};
  }
  /// At rest at (x, y, z), identity orientation, time 0.
  static constexpr TrajectoryPoint stationary(double x, double y, double z) noexcept {
    return TrajectoryPoint{{x, y, z}, {}, {}, {0.0, 0.0, 0.0, 1.0}, {}, 0.0};
  }

  friend constexpr bool operator==(const TrajectoryPoint&, const TrajectoryPoint&) = default;
};
HORUS_REFLECT(TrajectoryPoint, position, velocity, acceleration, orientation, angular_velocity, time_from_start)

static_assert(horus::reflect::is_fixed_size<MotorCommand>,
              "MotorCommand must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<DifferentialDriveCommand>,
              "DifferentialDriveCommand must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<ServoCommand>,
              "ServoCommand must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<PidConfig>, "PidConfig must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<TrajectoryPoint>,
              "TrajectoryPoint must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(MotorCommand, DifferentialDriveCommand, ServoCommand, JointCommand, PidConfig,
                        TrajectoryPoint)

}  // namespace horus::msg

HORUS_API_END
