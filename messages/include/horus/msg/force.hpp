// Force and haptics messages: WrenchStamped, ImpedanceParameters, ForceCommand,
// ContactInfo (with ContactState), HapticFeedback.
//
// The spec only names these ("All are POD types"); fields, sizes and helper
// meanings follow HORUS's force.rs. All are fixed-size (trivially copyable).
// As for every message, `T{}` is all zeros; the factories give HORUS's
// constructor values but never read a clock: stamp timestamp_ns yourself.
//
// Units: forces in N, torques in N*m, positions in m, angles in rad, stiffness
// in N/m (N*m/rad for the rotational axes), damping in N*s/m (N*m*s/rad),
// inertia in kg (kg*m^2), durations in s, timestamps in ns since the epoch.
// 6-element arrays are ordered [x, y, z, rx, ry, rz]. Text fields are
// NUL-terminated std::array<char, N>, written through set_fixed_str(): text that
// does not fit is refused, never cut.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "horus/fixed_string.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

namespace detail {
/// Stores a frame name, or throws std::invalid_argument naming the message and
/// the limit (the field is then unchanged).
template <std::size_t N>
void force_set_frame_or_throw(std::array<char, N>& field, std::string_view text, std::string_view what) {
  if (!set_fixed_str(field, text))
    throw std::invalid_argument(std::string(what) + " frame_id '" + std::string(text) + "' has " +
                                std::to_string(text.size()) + " characters; at most " + std::to_string(N - 1) +
                                " fit (and no NUL)");
}

/// alpha * a + (1 - alpha) * b, component-wise.
inline Vector3 force_blend(const Vector3& a, const Vector3& b, double alpha) noexcept {
  return Vector3{alpha * a.x + (1.0 - alpha) * b.x, alpha * a.y + (1.0 - alpha) * b.y,
                 alpha * a.z + (1.0 - alpha) * b.z};
}
}  // namespace detail

// ---------------------------------------------------------------------------
/// A force/torque measurement (wrench) from a force/torque sensor, with the
/// point where it acts, in the sensor frame frame_id.
struct WrenchStamped {
  Vector3 force{};                 ///< N
  Vector3 torque{};                ///< N*m
  Point3 point_of_application{};   ///< m, in the sensor frame
  std::array<char, 32> frame_id{}; ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// Force and torque acting at the origin, no frame, timestamp 0.
  static constexpr WrenchStamped make(const Vector3& force_n, const Vector3& torque_nm) noexcept {
    return WrenchStamped{force_n, torque_nm, Point3::origin(), {}, 0};
  }
  /// A pure force (zero torque).
  static constexpr WrenchStamped force_only(const Vector3& force_n) noexcept { return make(force_n, Vector3::zero()); }
  /// A pure torque (zero force).
  static constexpr WrenchStamped torque_only(const Vector3& torque_nm) noexcept {
    return make(Vector3::zero(), torque_nm);
  }

  /// A copy in the given frame. Throws std::invalid_argument when the name does
  /// not fit (at most 31 characters, no NUL); HORUS cuts it, which would name another frame.
  [[nodiscard]] WrenchStamped with_frame_id(std::string_view frame) const {
    WrenchStamped w = *this;
    detail::force_set_frame_or_throw(w.frame_id, frame, "WrenchStamped");
    return w;
  }
  /// Sets the frame; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  /// |force| in N.
  double force_magnitude() const noexcept { return force.magnitude(); }
  /// |torque| in N*m.
  double torque_magnitude() const noexcept { return torque.magnitude(); }

  /// True when |force| > max_force_n or |torque| > max_torque_nm. A non-finite
  /// reading (NaN, inf) counts as exceeding: a safety check must not pass on a
  /// broken sensor (HORUS's comparison would let NaN through).
  bool exceeds_limits(double max_force_n, double max_torque_nm) const noexcept {
    const double f = force_magnitude();
    const double t = torque_magnitude();
    return !std::isfinite(f) || !std::isfinite(t) || f > max_force_n || t > max_torque_nm;
  }

  /// First-order low-pass filter in place: this = alpha * this + (1 - alpha) *
  /// prev for force and torque. alpha is clamped to [0, 1] (1 keeps this
  /// sample, 0 keeps prev); a NaN alpha leaves the message unchanged.
  void filter(const WrenchStamped& prev, double alpha) noexcept {
    if (std::isnan(alpha)) return;
    const double a = std::clamp(alpha, 0.0, 1.0);
    force = detail::force_blend(force, prev.force, a);
    torque = detail::force_blend(torque, prev.torque, a);
  }

  friend constexpr bool operator==(const WrenchStamped&, const WrenchStamped&) = default;
};
HORUS_REFLECT(WrenchStamped, force, torque, point_of_application, frame_id, timestamp_ns)

// ---------------------------------------------------------------------------
/// Impedance control parameters: the diagonals of the stiffness, damping and
/// inertia matrices, and per-axis force/torque limits, all [x, y, z, rx, ry, rz].
struct ImpedanceParameters {
  std::array<double, 6> stiffness{};     ///< N/m, N*m/rad
  std::array<double, 6> damping{};       ///< N*s/m, N*m*s/rad
  std::array<double, 6> inertia{};       ///< kg, kg*m^2
  std::array<double, 6> force_limits{};  ///< N, N*m: [Fx_max, Fy_max, Fz_max, Tx_max, Ty_max, Tz_max]
  std::uint8_t enabled{};                ///< 1 = impedance control active
  std::uint64_t timestamp_ns{};

  /// HORUS's ImpedanceParameters::new(): moderate stiffness (1000 N/m, 100
  /// N*m/rad), damping (50, 5), inertia (1 kg, 0.1 kg*m^2), limits 50 N and
  /// 5 N*m; disabled.
  static constexpr ImpedanceParameters make() noexcept {
    ImpedanceParameters p{};
    p.stiffness = {1000.0, 1000.0, 1000.0, 100.0, 100.0, 100.0};
    p.damping = {50.0, 50.0, 50.0, 5.0, 5.0, 5.0};
    p.inertia = {1.0, 1.0, 1.0, 0.1, 0.1, 0.1};
    p.force_limits = {50.0, 50.0, 50.0, 5.0, 5.0, 5.0};
    return p;
  }
  /// make() with low stiffness (100, 10) and damping (20, 2): yields to contact.
  static constexpr ImpedanceParameters compliant() noexcept {
    ImpedanceParameters p = make();
    p.stiffness = {100.0, 100.0, 100.0, 10.0, 10.0, 10.0};
    p.damping = {20.0, 20.0, 20.0, 2.0, 2.0, 2.0};
    return p;
  }
  /// make() with high stiffness (5000, 500) and damping (100, 10): holds position.
  static constexpr ImpedanceParameters stiff() noexcept {
    ImpedanceParameters p = make();
    p.stiffness = {5000.0, 5000.0, 5000.0, 500.0, 500.0, 500.0};
    p.damping = {100.0, 100.0, 100.0, 10.0, 10.0, 10.0};
    return p;
  }

  constexpr void enable() noexcept { enabled = 1; }
  constexpr void disable() noexcept { enabled = 0; }
  constexpr bool is_enabled() const noexcept { return enabled != 0; }

  /// True when any component of the wrench is beyond its limit: |Fx| >
  /// force_limits[0], ..., |Tz| > force_limits[5]. A non-finite component counts
  /// as exceeding.
  bool exceeds_force_limits(const WrenchStamped& w) const noexcept {
    const std::array<double, 6> c{w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z};
    for (std::size_t i = 0; i < c.size(); ++i)
      if (!std::isfinite(c[i]) || std::abs(c[i]) > force_limits[i]) return true;
    return false;
  }

  friend constexpr bool operator==(const ImpedanceParameters&, const ImpedanceParameters&) = default;
};
HORUS_REFLECT(ImpedanceParameters, stiffness, damping, inertia, force_limits, enabled, timestamp_ns)

// ---------------------------------------------------------------------------
/// Hybrid force/position command. force_mode[i] selects, per axis [fx, fy, fz,
/// tx, ty, tz], force control (1) or position control (0); position-controlled
/// axes follow position_setpoint / orientation_setpoint.
struct ForceCommand {
  static constexpr std::uint8_t MODE_POSITION = 0;  ///< force_mode value: position control
  static constexpr std::uint8_t MODE_FORCE = 1;     ///< force_mode value: force control

  Vector3 target_force{};                 ///< N
  Vector3 target_torque{};                ///< N*m
  std::array<std::uint8_t, 6> force_mode{};
  Vector3 position_setpoint{};            ///< m
  Vector3 orientation_setpoint{};         ///< rad, Euler angles (roll, pitch, yaw)
  Vector3 max_deviation{};                ///< m, allowed deviation from the setpoint
  std::array<double, 6> gains{};          ///< [Kp_fx, Kp_fy, Kp_fz, Kp_tx, Kp_ty, Kp_tz]
  double timeout_seconds{};               ///< s, 0 = no timeout
  std::array<char, 32> frame_id{};        ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// Hybrid command: force control on the axes where force_axes[i] is 1, the
  /// given force target and position setpoint, zero torque and orientation,
  /// 1 cm maximum deviation, unit gains, no timeout.
  static constexpr ForceCommand hybrid(const std::array<std::uint8_t, 6>& force_axes, const Vector3& force_n,
                                       const Vector3& position_m) noexcept {
    ForceCommand c{};
    c.target_force = force_n;
    c.force_mode = force_axes;
    c.position_setpoint = position_m;
    c.max_deviation = Vector3{0.01, 0.01, 0.01};
    c.gains = {1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
    return c;
  }
  /// Pure force command: force control on x, y, z (torque axes position-controlled).
  static constexpr ForceCommand force_only(const Vector3& force_n) noexcept {
    return hybrid({1, 1, 1, 0, 0, 0}, force_n, Vector3::zero());
  }
  /// Surface following: normal_force_n along the unit surface normal. When
  /// the normal is mostly vertical (|z| > 0.8 after normalising) only z is
  /// force-controlled, else x, y and z. A zero normal gives a zero force target
  /// (force control on x, y, z).
  static ForceCommand surface_contact(double normal_force_n, const Vector3& surface_normal) noexcept {
    const Vector3 n = surface_normal.normalized();
    const Vector3 f{n.x * normal_force_n, n.y * normal_force_n, n.z * normal_force_n};
    using Axes = std::array<std::uint8_t, 6>;
    const Axes axes = std::abs(n.z) > 0.8 ? Axes{0, 0, 1, 0, 0, 0} : Axes{1, 1, 1, 0, 0, 0};
    return hybrid(axes, f, Vector3::zero());
  }

  /// A copy with the timeout in seconds (0 = none).
  [[nodiscard]] constexpr ForceCommand with_timeout(double seconds) const noexcept {
    ForceCommand c = *this;
    c.timeout_seconds = seconds;
    return c;
  }
  /// A copy in the given frame. Throws std::invalid_argument when the name does
  /// not fit (at most 31 characters, no NUL).
  [[nodiscard]] ForceCommand with_frame_id(std::string_view frame) const {
    ForceCommand c = *this;
    detail::force_set_frame_or_throw(c.frame_id, frame, "ForceCommand");
    return c;
  }
  /// Sets the frame; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  /// True when axis (0..5 = fx, fy, fz, tx, ty, tz) is force-controlled; false
  /// for a position-controlled axis and for an axis index out of range.
  constexpr bool is_force_axis(std::size_t axis) const noexcept {
    return axis < force_mode.size() && force_mode[axis] != MODE_POSITION;
  }
  /// True when the command expires (timeout_seconds > 0).
  constexpr bool has_timeout() const noexcept { return timeout_seconds > 0.0; }

  friend constexpr bool operator==(const ForceCommand&, const ForceCommand&) = default;
};
HORUS_REFLECT(ForceCommand, target_force, target_torque, force_mode, position_setpoint, orientation_setpoint,
              max_deviation, gains, timeout_seconds, frame_id, timestamp_ns)

// ---------------------------------------------------------------------------
/// Contact classification (HORUS ContactState, stored in ContactInfo::state).
enum class ContactState : std::uint8_t {
  NoContact = 0,
  InitialContact = 1,
  StableContact = 2,
  ContactLoss = 3,
  Sliding = 4,
  Impact = 5,
};
HORUS_REFLECT_ENUM(ContactState, NoContact, InitialContact, StableContact, ContactLoss, Sliding, Impact)

// ---------------------------------------------------------------------------
/// Detected contact: its state, force, estimated normal, point and surface
/// properties, in frame_id.
struct ContactInfo {
  std::uint8_t state{};                ///< a ContactState
  double contact_force{};              ///< N, magnitude
  Vector3 contact_normal{};            ///< unit vector (estimated)
  Point3 contact_point{};              ///< m (estimated)
  double stiffness{};                  ///< N/m (estimated)
  double damping{};                    ///< N*s/m (estimated)
  float confidence{};                  ///< 0 to 1
  std::uint64_t contact_start_time{};  ///< ns since the epoch when contact began, 0 = unknown
  std::array<char, 32> frame_id{};     ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// HORUS's ContactInfo::new(state, force): normal +Z, contact point at the
  /// origin, confidence 0.5, no stiffness or damping estimate, no start time.
  static constexpr ContactInfo make(ContactState s, double force_n) noexcept {
    ContactInfo c{};
    c.set_state(s);
    c.contact_force = force_n;
    c.contact_normal = Vector3{0.0, 0.0, 1.0};
    c.confidence = 0.5f;
    return c;
  }

  constexpr ContactState state_enum() const noexcept { return static_cast<ContactState>(state); }
  constexpr void set_state(ContactState s) noexcept { state = static_cast<std::uint8_t>(s); }

  /// In contact: InitialContact, StableContact or Sliding (not NoContact,
  /// ContactLoss, Impact, or an unknown state value).
  constexpr bool is_in_contact() const noexcept {
    const ContactState s = state_enum();
    return s == ContactState::InitialContact || s == ContactState::StableContact || s == ContactState::Sliding;
  }

  /// Seconds from contact_start_time to timestamp_ns; 0 when the start is
  /// unknown (0) or after the timestamp.
  constexpr double contact_duration_seconds() const noexcept {
    if (contact_start_time == 0 || timestamp_ns < contact_start_time) return 0.0;
    return static_cast<double>(timestamp_ns - contact_start_time) / 1e9;
  }

  /// Sets the frame; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  friend constexpr bool operator==(const ContactInfo&, const ContactInfo&) = default;
};
HORUS_REFLECT(ContactInfo, state, contact_force, contact_normal, contact_point, stiffness, damping, confidence,
              contact_start_time, frame_id, timestamp_ns)

// ---------------------------------------------------------------------------
/// Haptic output: vibration and/or a force to render on an operator device.
struct HapticFeedback {
  static constexpr std::uint8_t PATTERN_CONSTANT = 0;
  static constexpr std::uint8_t PATTERN_PULSE = 1;
  static constexpr std::uint8_t PATTERN_RAMP = 2;

  float vibration_intensity{};   ///< 0 to 1
  float vibration_frequency{};   ///< Hz
  float duration_seconds{};      ///< s
  Vector3 force_feedback{};      ///< N
  std::uint8_t pattern_type{};   ///< PATTERN_CONSTANT, PATTERN_PULSE or PATTERN_RAMP
  std::uint8_t enabled{};        ///< 1 = output on
  std::uint64_t timestamp_ns{};

  /// Constant vibration, enabled. The intensity is clamped to [0, 1] (NaN becomes 0).
  static constexpr HapticFeedback vibration(float intensity, float frequency_hz, float duration_s) noexcept {
    HapticFeedback h{};
    h.vibration_intensity = intensity > 0.0f ? std::min(intensity, 1.0f) : 0.0f;
    h.vibration_frequency = frequency_hz;
    h.duration_seconds = duration_s;
    h.pattern_type = PATTERN_CONSTANT;
    h.enabled = 1;
    return h;
  }
  /// Force feedback (no vibration), enabled.
  static constexpr HapticFeedback force(const Vector3& force_n, float duration_s) noexcept {
    HapticFeedback h{};
    h.force_feedback = force_n;
    h.duration_seconds = duration_s;
    h.pattern_type = PATTERN_CONSTANT;
    h.enabled = 1;
    return h;
  }
  /// Pulsed vibration: vibration() with PATTERN_PULSE.
  static constexpr HapticFeedback pulse(float intensity, float frequency_hz, float duration_s) noexcept {
    HapticFeedback h = vibration(intensity, frequency_hz, duration_s);
    h.pattern_type = PATTERN_PULSE;
    return h;
  }

  constexpr bool is_enabled() const noexcept { return enabled != 0; }
  /// |force_feedback| in N.
  double force_magnitude() const noexcept { return force_feedback.magnitude(); }

  friend constexpr bool operator==(const HapticFeedback&, const HapticFeedback&) = default;
};
HORUS_REFLECT(HapticFeedback, vibration_intensity, vibration_frequency, duration_seconds, force_feedback, pattern_type,
              enabled, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<WrenchStamped>,
              "WrenchStamped must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<ImpedanceParameters>,
              "ImpedanceParameters must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<ForceCommand>,
              "ForceCommand must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<ContactInfo>, "ContactInfo must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<HapticFeedback>,
              "HapticFeedback must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(WrenchStamped, ImpedanceParameters, ForceCommand, ContactInfo, HapticFeedback)

}  // namespace horus::msg

HORUS_API_END
