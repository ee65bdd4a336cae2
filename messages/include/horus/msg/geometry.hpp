// Geometry messages: points, vectors, rotations, poses, velocities, transforms,
// accelerations, and poses / velocities with covariance.
//
// Every message is a plain aggregate: `T{}` is all zeros (note that a zero
// Quaternion is not a rotation; use Quaternion::identity()). Field names and
// order follow the spec tables; they fix the type hash and the wire layout, so
// do not reorder them. Helpers are static factories named like the spec's
// constructors (`make` stands for the spec's `new`).
//
// Conventions: lengths in metres, angles in radians, velocities in m/s and
// rad/s, timestamps in nanoseconds since the epoch. Quaternions are stored
// (x, y, z, w); Euler angles are roll (about X), pitch (about Y), yaw (about Z)
// applied in ZYX order, as in ROS (tf2) and Eigen's AngleAxis(yaw, Z) *
// AngleAxis(pitch, Y) * AngleAxis(roll, X).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>
#include <string_view>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

/// Wraps an angle into [-pi, pi]. Uses the IEEE remainder, which is exact, so
/// it stays correct for huge angles (1e10 rad) where a loop or fmod-and-shift
/// would lose precision. pi stays pi and -pi stays -pi; a non-finite angle
/// gives NaN.
inline double normalize_angle(double angle_rad) noexcept {
  return std::remainder(angle_rad, 2.0 * std::numbers::pi);
}

/// Roll, pitch, yaw in radians (see the convention at the top of the file).
struct EulerAngles {
  double roll{};
  double pitch{};
  double yaw{};
  friend constexpr bool operator==(const EulerAngles&, const EulerAngles&) = default;
};

// ---------------------------------------------------------------------------
/// A point in 3D space, in metres.
struct Point3 {
  double x{};
  double y{};
  double z{};

  static constexpr Point3 make(double x_m, double y_m, double z_m) noexcept { return Point3{x_m, y_m, z_m}; }
  static constexpr Point3 origin() noexcept { return Point3{}; }

  /// Euclidean distance in metres.
  double distance_to(const Point3& other) const noexcept { return std::hypot(x - other.x, y - other.y, z - other.z); }

  friend constexpr bool operator==(const Point3&, const Point3&) = default;
};
HORUS_REFLECT(Point3, x, y, z)

// ---------------------------------------------------------------------------
/// A direction or displacement in 3D space.
struct Vector3 {
  double x{};
  double y{};
  double z{};

  static constexpr Vector3 make(double x_, double y_, double z_) noexcept { return Vector3{x_, y_, z_}; }
  static constexpr Vector3 zero() noexcept { return Vector3{}; }

  double magnitude() const noexcept { return std::hypot(x, y, z); }
  constexpr double dot(const Vector3& o) const noexcept { return x * o.x + y * o.y + z * o.z; }
  constexpr Vector3 cross(const Vector3& o) const noexcept {
    return Vector3{y * o.z - z * o.y, z * o.x - x * o.z, x * o.y - y * o.x};
  }

  /// Scales to unit length in place; the zero vector stays zero (it has no direction).
  void normalize() noexcept {
    const double m = magnitude();
    if (m > 0.0) {
      x /= m;
      y /= m;
      z /= m;
    }
  }
  /// A unit-length copy (zero stays zero).
  Vector3 normalized() const noexcept {
    Vector3 v = *this;
    v.normalize();
    return v;
  }

  friend constexpr bool operator==(const Vector3&, const Vector3&) = default;
};
HORUS_REFLECT(Vector3, x, y, z)

// ---------------------------------------------------------------------------
/// A rotation as a unit quaternion (x, y, z, w). `Quaternion{}` is all zeros,
/// which is not a rotation: start from identity() or from_euler().
struct Quaternion {
  double x{};
  double y{};
  double z{};
  double w{};

  static constexpr Quaternion identity() noexcept { return Quaternion{0.0, 0.0, 0.0, 1.0}; }
  static constexpr Quaternion make(double x_, double y_, double z_, double w_) noexcept {
    return Quaternion{x_, y_, z_, w_};
  }

  /// The rotation yaw about Z, then pitch about Y, then roll about X (ZYX, as ROS).
  static Quaternion from_euler(double roll, double pitch, double yaw) noexcept {
    const double cr = std::cos(roll * 0.5), sr = std::sin(roll * 0.5);
    const double cp = std::cos(pitch * 0.5), sp = std::sin(pitch * 0.5);
    const double cy = std::cos(yaw * 0.5), sy = std::sin(yaw * 0.5);
    return Quaternion{
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    };
  }

  /// Roll, pitch, yaw of this rotation (normalised first; zero gives all 0).
  /// Pitch is in [-pi/2, pi/2], roll and yaw in [-pi, pi]. At gimbal lock
  /// (pitch = +-pi/2) only yaw -+ roll is defined: roll is reported as 0.
  EulerAngles to_euler() const noexcept {
    const Quaternion q = normalized();
    const double sinr_cosp = 2.0 * (q.w * q.x + q.y * q.z);
    const double cosr_cosp = 1.0 - 2.0 * (q.x * q.x + q.y * q.y);
    const double sinp = 2.0 * (q.w * q.y - q.z * q.x);
    const double siny_cosp = 2.0 * (q.w * q.z + q.x * q.y);
    const double cosy_cosp = 1.0 - 2.0 * (q.y * q.y + q.z * q.z);
    // cos(pitch) from the roll terms keeps pitch accurate near +-pi/2, where asin(sinp) is not.
    const double cosp = std::hypot(sinr_cosp, cosr_cosp);
    const double pitch = std::atan2(sinp, cosp);
    if (cosp < 1e-9) return EulerAngles{0.0, pitch, msg::normalize_angle(2.0 * std::atan2(q.z, q.w))};
    return EulerAngles{std::atan2(sinr_cosp, cosr_cosp), pitch, std::atan2(siny_cosp, cosy_cosp)};
  }

  double norm() const noexcept { return std::sqrt(x * x + y * y + z * z + w * w); }

  /// Scales to unit length in place. The zero quaternion becomes identity (the
  /// only sensible rotation for "no data"); a non-finite one stays non-finite.
  void normalize() noexcept {
    const double n = norm();
    if (n == 0.0) {
      *this = identity();
      return;
    }
    x /= n;
    y /= n;
    z /= n;
    w /= n;
  }
  Quaternion normalized() const noexcept {
    Quaternion q = *this;
    q.normalize();
    return q;
  }

  /// All components finite and unit length (within 1e-6).
  bool is_valid() const noexcept {
    return std::isfinite(x) && std::isfinite(y) && std::isfinite(z) && std::isfinite(w) &&
           std::abs(norm() - 1.0) <= 1e-6;
  }

  friend constexpr bool operator==(const Quaternion&, const Quaternion&) = default;
};
HORUS_REFLECT(Quaternion, x, y, z, w)

// ---------------------------------------------------------------------------
/// Basic 2D velocity command for a mobile base.
struct CmdVel {
  std::uint64_t stamp_nanos{};  ///< ns since epoch
  float linear{};               ///< forward velocity, m/s
  float angular{};              ///< rotation velocity about Z, rad/s

  /// The spec's CmdVel::new(linear, angular); the timestamp is left 0.
  static constexpr CmdVel make(float linear_mps, float angular_radps) noexcept {
    return CmdVel{0, linear_mps, angular_radps};
  }
  static constexpr CmdVel zero() noexcept { return CmdVel{}; }
  static constexpr CmdVel with_timestamp(float linear_mps, float angular_radps, std::uint64_t stamp_ns) noexcept {
    return CmdVel{stamp_ns, linear_mps, angular_radps};
  }

  friend constexpr bool operator==(const CmdVel&, const CmdVel&) = default;
};
HORUS_REFLECT(CmdVel, stamp_nanos, linear, angular)

// ---------------------------------------------------------------------------
/// 3D velocity: linear [x, y, z] in m/s, angular [roll, pitch, yaw] rates in rad/s.
struct Twist {
  std::array<double, 3> linear{};
  std::array<double, 3> angular{};
  std::uint64_t timestamp_ns{};

  static constexpr Twist make(const std::array<double, 3>& linear_mps, const std::array<double, 3>& angular_radps) noexcept {
    return Twist{linear_mps, angular_radps, 0};
  }
  /// Planar velocity: forward speed (m/s) and yaw rate (rad/s).
  static constexpr Twist new_2d(double linear_x_mps, double angular_z_radps) noexcept {
    return Twist{{linear_x_mps, 0.0, 0.0}, {0.0, 0.0, angular_z_radps}, 0};
  }
  static constexpr Twist stop() noexcept { return Twist{}; }

  /// All six velocity components finite.
  bool is_valid() const noexcept {
    for (double v : linear)
      if (!std::isfinite(v)) return false;
    for (double v : angular)
      if (!std::isfinite(v)) return false;
    return true;
  }

  friend constexpr bool operator==(const Twist&, const Twist&) = default;
};
HORUS_REFLECT(Twist, linear, angular, timestamp_ns)

// ---------------------------------------------------------------------------
/// Planar position (m) and heading (rad).
struct Pose2D {
  double x{};
  double y{};
  double theta{};
  std::uint64_t timestamp_ns{};

  static constexpr Pose2D make(double x_m, double y_m, double theta_rad) noexcept {
    return Pose2D{x_m, y_m, theta_rad, 0};
  }
  static constexpr Pose2D origin() noexcept { return Pose2D{}; }

  /// Euclidean distance between the positions, in metres (heading ignored).
  double distance_to(const Pose2D& other) const noexcept { return std::hypot(x - other.x, y - other.y); }

  /// Wraps theta into [-pi, pi] (see msg::normalize_angle).
  void normalize_angle() noexcept { theta = msg::normalize_angle(theta); }

  /// x, y and theta finite.
  bool is_valid() const noexcept { return std::isfinite(x) && std::isfinite(y) && std::isfinite(theta); }

  friend constexpr bool operator==(const Pose2D&, const Pose2D&) = default;
};
HORUS_REFLECT(Pose2D, x, y, theta, timestamp_ns)

// ---------------------------------------------------------------------------
/// Position and orientation in 3D (HORUS layout; the spec has no table for it).
struct Pose3D {
  Point3 position{};
  Quaternion orientation{};
  std::uint64_t timestamp_ns{};

  static constexpr Pose3D identity() noexcept { return Pose3D{Point3::origin(), Quaternion::identity(), 0}; }
  static constexpr Pose3D make(const Point3& position_m, const Quaternion& rotation) noexcept {
    return Pose3D{position_m, rotation, 0};
  }
  /// The planar pose lifted to 3D: z = 0, a yaw rotation of theta; the timestamp is kept.
  static Pose3D from_pose_2d(const Pose2D& p) noexcept {
    return Pose3D{Point3{p.x, p.y, 0.0}, Quaternion::from_euler(0.0, 0.0, p.theta), p.timestamp_ns};
  }

  /// Distance between the positions, in metres (orientation ignored).
  double distance_to(const Pose3D& other) const noexcept { return position.distance_to(other.position); }

  friend constexpr bool operator==(const Pose3D&, const Pose3D&) = default;
};
HORUS_REFLECT(Pose3D, position, orientation, timestamp_ns)

// ---------------------------------------------------------------------------
/// A rigid transform: translation [x, y, z] in metres, rotation quaternion [x, y, z, w].
struct TransformStamped {
  std::array<double, 3> translation{};
  std::array<double, 4> rotation{};
  std::uint64_t timestamp_ns{};

  static constexpr TransformStamped identity() noexcept {
    return TransformStamped{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 1.0}, 0};
  }
  static constexpr TransformStamped make(const std::array<double, 3>& translation_m,
                                         const std::array<double, 4>& rotation_xyzw) noexcept {
    return TransformStamped{translation_m, rotation_xyzw, 0};
  }
  /// The planar pose as a transform: z = 0, a yaw rotation of theta; the timestamp is kept.
  static TransformStamped from_pose_2d(const Pose2D& p) noexcept {
    const Quaternion q = Quaternion::from_euler(0.0, 0.0, p.theta);
    return TransformStamped{{p.x, p.y, 0.0}, {q.x, q.y, q.z, q.w}, p.timestamp_ns};
  }

  /// The rotation as a Quaternion value.
  constexpr Quaternion rotation_quaternion() const noexcept {
    return Quaternion{rotation[0], rotation[1], rotation[2], rotation[3]};
  }

  /// Scales the rotation to unit length; a zero rotation becomes identity.
  void normalize_rotation() noexcept {
    const Quaternion q = rotation_quaternion().normalized();
    rotation = {q.x, q.y, q.z, q.w};
  }

  /// Translation finite and rotation a finite unit quaternion (within 1e-6).
  bool is_valid() const noexcept {
    for (double v : translation)
      if (!std::isfinite(v)) return false;
    return rotation_quaternion().is_valid();
  }

  friend constexpr bool operator==(const TransformStamped&, const TransformStamped&) = default;
};
HORUS_REFLECT(TransformStamped, translation, rotation, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<Point3>, "Point3 must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Vector3>, "Vector3 must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Quaternion>, "Quaternion must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<CmdVel>, "CmdVel must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Twist>, "Twist must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Pose2D>, "Pose2D must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Pose3D>, "Pose3D must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<TransformStamped>,
              "TransformStamped must be trivially copyable and standard layout");

// ===========================================================================
// Covariance, acceleration and stamped messages (HORUS geometry.rs; the spec
// only names them). 6x6 covariances are row-major; the diagonal holds the
// variances, at indices 0, 7, 14, 21, 28, 35.

namespace detail {
/// Stores text into a fixed field, or throws std::invalid_argument (naming
/// `what` and the limit) and leaves the field unchanged when it does not fit.
template <std::size_t N>
void assign_fixed_str_or_throw(std::array<char, N>& field, std::string_view text, std::string_view what) {
  if (!set_fixed_str(field, text))
    throw std::invalid_argument(std::string(what) + " '" + std::string(text) + "' has " + std::to_string(text.size()) +
                                " characters; at most " + std::to_string(N - 1) + " fit (and no NUL)");
}
}  // namespace detail

// ---------------------------------------------------------------------------
/// A 3D pose with its 6x6 uncertainty (localisation output: AMCL, EKF).
/// Covariance order: x, y, z (m), roll, pitch, yaw (rad).
struct PoseWithCovariance {
  Pose3D pose{};
  std::array<double, 36> covariance{};  ///< 6x6, row-major; units m^2, rad^2 and m*rad
  std::array<char, 32> frame_id{};      ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// The pose with zero covariance and no frame; the message takes the pose's timestamp.
  static constexpr PoseWithCovariance make(const Pose3D& p) noexcept {
    return PoseWithCovariance{p, {}, {}, p.timestamp_ns};
  }

  /// Sets the frame; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }
  /// A copy with the frame set; throws std::invalid_argument when the name does not fit
  /// (HORUS Rust cuts it to 31 bytes instead; a cut frame name would name another frame).
  [[nodiscard]] PoseWithCovariance with_frame_id(std::string_view frame) const {
    PoseWithCovariance m = *this;
    detail::assign_fixed_str_or_throw(m.frame_id, frame, "PoseWithCovariance frame_id");
    return m;
  }

  /// Variances of x, y, z in m^2 (covariance diagonal 0, 7, 14).
  constexpr std::array<double, 3> position_variance() const noexcept {
    return {covariance[0], covariance[7], covariance[14]};
  }
  /// Variances of roll, pitch, yaw in rad^2 (covariance diagonal 21, 28, 35).
  constexpr std::array<double, 3> orientation_variance() const noexcept {
    return {covariance[21], covariance[28], covariance[35]};
  }

  /// "PoseWithCovariance(map, position (1.00, 2.00, 0.00) m, var xyz (0.01, 0.01, 0) m^2, var rpy (0, 0, 0.05) rad^2)".
  std::string log_summary() const;

  friend constexpr bool operator==(const PoseWithCovariance&, const PoseWithCovariance&) = default;
};
HORUS_REFLECT(PoseWithCovariance, pose, covariance, frame_id, timestamp_ns)

// ---------------------------------------------------------------------------
/// A 3D velocity with its 6x6 uncertainty (sensor-fusion input).
/// Covariance order: vx, vy, vz (m/s), wx, wy, wz (rad/s).
struct TwistWithCovariance {
  Twist twist{};
  std::array<double, 36> covariance{};  ///< 6x6, row-major; units (m/s)^2, (rad/s)^2 and cross terms
  std::array<char, 32> frame_id{};      ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// The twist with zero covariance and no frame; the message takes the twist's timestamp.
  static constexpr TwistWithCovariance make(const Twist& t) noexcept {
    return TwistWithCovariance{t, {}, {}, t.timestamp_ns};
  }

  /// Sets the frame; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }
  /// A copy with the frame set; throws std::invalid_argument when the name does not fit.
  [[nodiscard]] TwistWithCovariance with_frame_id(std::string_view frame) const {
    TwistWithCovariance m = *this;
    detail::assign_fixed_str_or_throw(m.frame_id, frame, "TwistWithCovariance frame_id");
    return m;
  }

  /// Variances of vx, vy, vz in (m/s)^2 (covariance diagonal 0, 7, 14).
  constexpr std::array<double, 3> linear_variance() const noexcept {
    return {covariance[0], covariance[7], covariance[14]};
  }
  /// Variances of wx, wy, wz in (rad/s)^2 (covariance diagonal 21, 28, 35).
  constexpr std::array<double, 3> angular_variance() const noexcept {
    return {covariance[21], covariance[28], covariance[35]};
  }

  /// "TwistWithCovariance(base_link, linear (0.50, 0.00, 0.00) m/s, angular (0.00, 0.00, 0.20) rad/s, var ...)".
  std::string log_summary() const;

  friend constexpr bool operator==(const TwistWithCovariance&, const TwistWithCovariance&) = default;
};
HORUS_REFLECT(TwistWithCovariance, twist, covariance, frame_id, timestamp_ns)

// ---------------------------------------------------------------------------
/// 3D acceleration: linear [x, y, z] in m/s^2, angular [roll, pitch, yaw] in rad/s^2.
struct Accel {
  std::array<double, 3> linear{};
  std::array<double, 3> angular{};
  std::uint64_t timestamp_ns{};

  /// The spec's Accel::new(linear, angular); the timestamp is left 0.
  static constexpr Accel make(const std::array<double, 3>& linear_mps2,
                              const std::array<double, 3>& angular_radps2) noexcept {
    return Accel{linear_mps2, angular_radps2, 0};
  }

  /// All six components finite (NaN or infinity anywhere gives false).
  bool is_valid() const noexcept {
    for (double v : linear)
      if (!std::isfinite(v)) return false;
    for (double v : angular)
      if (!std::isfinite(v)) return false;
    return true;
  }

  friend constexpr bool operator==(const Accel&, const Accel&) = default;
};
HORUS_REFLECT(Accel, linear, angular, timestamp_ns)

// ---------------------------------------------------------------------------
/// An acceleration in a named frame.
struct AccelStamped {
  Accel accel{};
  std::array<char, 32> frame_id{};  ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// The acceleration with no frame; the message takes the acceleration's timestamp.
  static constexpr AccelStamped make(const Accel& a) noexcept { return AccelStamped{a, {}, a.timestamp_ns}; }

  /// Sets the frame; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }
  /// A copy with the frame set; throws std::invalid_argument when the name does not fit.
  [[nodiscard]] AccelStamped with_frame_id(std::string_view frame) const {
    AccelStamped m = *this;
    detail::assign_fixed_str_or_throw(m.frame_id, frame, "AccelStamped frame_id");
    return m;
  }

  friend constexpr bool operator==(const AccelStamped&, const AccelStamped&) = default;
};
HORUS_REFLECT(AccelStamped, accel, frame_id, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<PoseWithCovariance>,
              "PoseWithCovariance must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<TwistWithCovariance>,
              "TwistWithCovariance must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Accel>, "Accel must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<AccelStamped>,
              "AccelStamped must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(CmdVel, Twist, Pose2D, Pose3D, Point3, Vector3, Quaternion, TransformStamped, Accel,
                        AccelStamped, PoseWithCovariance, TwistWithCovariance)

}  // namespace horus::msg

HORUS_API_END
