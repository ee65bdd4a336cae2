// Diagnostics messages: Heartbeat, NodeHeartbeat, Status and DiagnosticStatus
// (one message under HORUS's old and new names), EmergencyStop, SafetyStatus,
// ResourceUsage, DiagnosticValue, DiagnosticReport.
//
// All fixed-size (trivially copyable). As for every message, `T{}` is all zeros;
// the factories (make(), engage(), ...) give HORUS's Rust constructor values,
// except that they never read a clock for timestamp_ns: stamp it yourself.
// Text fields are NUL-terminated std::array<char, N> written through
// set_fixed_str(): text that does not fit is refused, never cut (the one
// exception, EmergencyStop::engage, is documented there).
#pragma once

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// Liveness signal of a node: published periodically, sequence counts up by one
/// per beat so a receiver can spot lost beats.
struct Heartbeat {
  std::array<char, 32> node_name{};  ///< NUL-terminated, at most 31 characters
  std::uint32_t node_id{};
  std::uint64_t sequence{};
  std::uint8_t alive{};   ///< 1 = alive
  double uptime{};        ///< s since the node started
  std::uint64_t timestamp_ns{};

  /// A live heartbeat (alive = 1, sequence 0) for the node, or nullopt when the
  /// name does not fit (at most 31 characters, no NUL).
  static constexpr std::optional<Heartbeat> create(std::string_view name, std::uint32_t id) noexcept {
    Heartbeat hb{};
    if (!hb.set_node_name(name)) return std::nullopt;
    hb.node_id = id;
    hb.alive = 1;
    return hb;
  }

  /// Throwing form of create(): std::invalid_argument when the name does not fit.
  static Heartbeat make(std::string_view name, std::uint32_t id) {
    if (auto hb = create(name, id)) return *hb;
    throw std::invalid_argument("Heartbeat node name '" + std::string(name) + "' has " + std::to_string(name.size()) +
                                " characters; at most 31 fit");
  }

  /// Sets the node name; returns false, changing nothing, when it does not fit.
  constexpr bool set_node_name(std::string_view name) noexcept { return set_fixed_str(node_name, name); }
  constexpr std::string_view node_name_str() const noexcept { return fixed_str_view(node_name); }

  /// Next beat: sequence + 1, alive = 1, uptime in seconds.
  constexpr void update(double uptime_s) noexcept {
    ++sequence;
    alive = 1;
    uptime = uptime_s;
  }

  friend constexpr bool operator==(const Heartbeat&, const Heartbeat&) = default;
};
HORUS_REFLECT(Heartbeat, node_name, node_id, sequence, alive, uptime, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<Heartbeat>, "Heartbeat must be trivially copyable and standard layout");

namespace detail {
/// Stores text into a fixed field, or throws std::invalid_argument naming the
/// message, the field and the limit (the field is then unchanged).
template <std::size_t N>
void diag_set_text_or_throw(std::array<char, N>& field, std::string_view text, std::string_view what) {
  if (!set_fixed_str(field, text))
    throw std::invalid_argument(std::string(what) + " '" + std::string(text) + "' has " +
                                std::to_string(text.size()) + " characters; at most " + std::to_string(N - 1) +
                                " fit (and no NUL)");
}

/// The longest prefix of text of at most max_bytes bytes that does not split a
/// UTF-8 character: text itself when it is short enough, else cut before the
/// character that would straddle the limit (a cut lands only where the next
/// byte is not a continuation byte, whose top bits are 10). A well-formed UTF-8 text thus
/// gives a well-formed prefix, at most 3 bytes shorter than max_bytes; it is
/// empty when max_bytes is 0. The bytes are not otherwise validated.
constexpr std::string_view diag_utf8_prefix(std::string_view text, std::size_t max_bytes) noexcept {
  if (text.size() <= max_bytes) return text;
  std::size_t len = max_bytes;
  while (len > 0 && (static_cast<unsigned char>(text[len]) & 0xC0u) == 0x80u) --len;
  return text.substr(0, len);
}

/// Stores text that must always go out (an emergency stop's reason): as is when
/// it fits, else its longest prefix that fits with "..." after it, visibly
/// marked as shortened. The prefix ends before any NUL and never splits a
/// UTF-8 sequence.
template <std::size_t N>
constexpr void diag_set_text_marked(std::array<char, N>& field, std::string_view text) noexcept {
  static_assert(N > 4, "field too small for a marked text");
  if (set_fixed_str(field, text)) return;
  const std::string_view head = diag_utf8_prefix(text.substr(0, text.find('\0')), N - 4);
  const std::size_t len = head.size();
  field.fill('\0');
  std::copy(head.begin(), head.begin() + static_cast<std::ptrdiff_t>(len), field.begin());
  field[len] = '.';
  field[len + 1] = '.';
  field[len + 2] = '.';
}

/// Seconds since the Unix epoch (system clock).
inline std::uint64_t diag_epoch_seconds() noexcept {
  const auto s = std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch());
  return s.count() < 0 ? 0u : static_cast<std::uint64_t>(s.count());
}

/// The enumerator name of a reflected enum value, or its number when it has none.
template <class E>
std::string diag_enum_text(E e) {
  const std::string_view name = to_string(e);
  return name.empty() ? std::to_string(static_cast<unsigned>(e)) : std::string(name);
}
}  // namespace detail

// ---------------------------------------------------------------------------
/// Severity of a Status or DiagnosticReport (HORUS StatusLevel, stored as u8).
enum class StatusLevel : std::uint8_t { Ok = 0, Warn = 1, Error = 2, Fatal = 3 };
HORUS_REFLECT_ENUM(StatusLevel, Ok, Warn, Error, Fatal)

/// Execution state of a node (HORUS NodeState, stored in NodeHeartbeat::state).
enum class NodeState : std::uint8_t { Idle = 0, Initializing = 1, Running = 2, Paused = 3, Stopped = 4, Error = 5 };
HORUS_REFLECT_ENUM(NodeState, Idle, Initializing, Running, Paused, Stopped, Error)

/// Health of a node (HORUS HealthStatus, stored in NodeHeartbeat::health).
enum class HealthStatus : std::uint8_t { Healthy = 0, Warning = 1, Error = 2, Critical = 3, Unknown = 4 };
HORUS_REFLECT_ENUM(HealthStatus, Healthy, Warning, Error, Critical, Unknown)

// ---------------------------------------------------------------------------
/// Detailed per-node health record, as the HORUS monitor reads it. Timestamps
/// are Unix epoch SECONDS (not nanoseconds), as in HORUS; rates are in Hz.
///
/// NodeHeartbeat{} is all zeros, i.e. state Idle and health Healthy; HORUS's
/// Rust default has health Unknown: build one with make().
struct NodeHeartbeat {
  std::uint8_t state{};                  ///< a NodeState
  std::uint8_t health{};                 ///< a HealthStatus
  std::uint32_t tick_count{};            ///< ticks executed so far
  float target_rate{};                   ///< Hz, expected tick rate
  float actual_rate{};                   ///< Hz, measured tick rate
  std::uint32_t error_count{};
  std::uint64_t last_tick_timestamp{};   ///< s since the Unix epoch, last successful tick
  std::uint64_t heartbeat_timestamp{};   ///< s since the Unix epoch, when this record was written

  /// State and health, both timestamps set to now_s (epoch seconds), counters 0.
  static constexpr NodeHeartbeat make(NodeState s, HealthStatus h, std::uint64_t now_s) noexcept {
    NodeHeartbeat hb{};
    hb.set_state(s);
    hb.set_health(h);
    hb.last_tick_timestamp = now_s;
    hb.heartbeat_timestamp = now_s;
    return hb;
  }
  /// As make(s, h, now_s) with the system clock's current epoch seconds (HORUS's NodeHeartbeat::new).
  static NodeHeartbeat make(NodeState s, HealthStatus h) noexcept { return make(s, h, detail::diag_epoch_seconds()); }

  constexpr NodeState state_enum() const noexcept { return static_cast<NodeState>(state); }
  constexpr void set_state(NodeState s) noexcept { state = static_cast<std::uint8_t>(s); }
  constexpr HealthStatus health_enum() const noexcept { return static_cast<HealthStatus>(health); }
  constexpr void set_health(HealthStatus h) noexcept { health = static_cast<std::uint8_t>(h); }

  /// Sets heartbeat_timestamp to now_s (epoch seconds).
  constexpr void update_timestamp(std::uint64_t now_s) noexcept { heartbeat_timestamp = now_s; }
  /// Sets heartbeat_timestamp to the system clock's current epoch seconds.
  void update_timestamp() noexcept { update_timestamp(detail::diag_epoch_seconds()); }

  /// True when the heartbeat is at most max_age_s seconds older than now_s. A
  /// heartbeat stamped in the future (clock skew) counts as fresh.
  constexpr bool is_fresh(std::uint64_t max_age_s, std::uint64_t now_s) const noexcept {
    return now_s <= heartbeat_timestamp || now_s - heartbeat_timestamp <= max_age_s;
  }
  /// is_fresh against the system clock.
  bool is_fresh(std::uint64_t max_age_s) const noexcept { return is_fresh(max_age_s, detail::diag_epoch_seconds()); }

  friend constexpr bool operator==(const NodeHeartbeat&, const NodeHeartbeat&) = default;
};
HORUS_REFLECT(NodeHeartbeat, state, health, tick_count, target_rate, actual_rate, error_count, last_tick_timestamp,
              heartbeat_timestamp)

// ---------------------------------------------------------------------------
namespace detail {
/// Level constants and helpers shared by Status and DiagnosticStatus (one
/// message under HORUS's old and new names). Self holds the fields level, code,
/// message (128 bytes) and component (32 bytes). An empty base: it adds no
/// bytes and keeps Self an aggregate with standard layout.
template <class Self>
struct StatusOps {
  static constexpr std::uint8_t LEVEL_OK = 0;
  static constexpr std::uint8_t LEVEL_WARN = 1;
  static constexpr std::uint8_t LEVEL_ERROR = 2;
  static constexpr std::uint8_t LEVEL_FATAL = 3;

  /// A status with level, code and message, or nullopt when the message does
  /// not fit (at most 127 characters, no NUL). No component, timestamp 0.
  static constexpr std::optional<Self> create(StatusLevel lvl, std::uint32_t status_code,
                                              std::string_view text) noexcept {
    Self s{};
    if (!s.set_message(text)) return std::nullopt;
    s.set_level(lvl);
    s.code = status_code;
    return s;
  }
  /// Throwing form of create() (HORUS's Status::new): std::invalid_argument when
  /// the message does not fit. HORUS cuts it at 127 bytes; here nothing is cut.
  static Self make(StatusLevel lvl, std::uint32_t status_code, std::string_view text) {
    Self s{};
    detail::diag_set_text_or_throw(s.message, text, std::string(short_name()) + " message");
    s.set_level(lvl);
    s.code = status_code;
    return s;
  }
  /// Level Ok, code 0. Throws std::invalid_argument when the message does not fit.
  static Self ok(std::string_view text) { return make(StatusLevel::Ok, 0, text); }
  /// Level Warn. Throws std::invalid_argument when the message does not fit.
  static Self warn(std::uint32_t status_code, std::string_view text) {
    return make(StatusLevel::Warn, status_code, text);
  }
  /// Level Error. Throws std::invalid_argument when the message does not fit.
  static Self error(std::uint32_t status_code, std::string_view text) {
    return make(StatusLevel::Error, status_code, text);
  }
  /// Level Fatal. Throws std::invalid_argument when the message does not fit.
  static Self fatal(std::uint32_t status_code, std::string_view text) {
    return make(StatusLevel::Fatal, status_code, text);
  }

  /// A copy with the component name set. Throws std::invalid_argument when the
  /// name does not fit (at most 31 characters, no NUL).
  [[nodiscard]] Self with_component(std::string_view name) const {
    Self s = self();
    detail::diag_set_text_or_throw(s.component, name, std::string(short_name()) + " component");
    return s;
  }

  constexpr StatusLevel level_enum() const noexcept { return static_cast<StatusLevel>(self().level); }
  constexpr void set_level(StatusLevel lvl) noexcept { self().level = static_cast<std::uint8_t>(lvl); }

  /// Sets the message; returns false, changing nothing, when it does not fit (127 characters at most, no NUL).
  constexpr bool set_message(std::string_view text) noexcept { return set_fixed_str(self().message, text); }
  constexpr std::string_view message_str() const noexcept { return fixed_str_view(self().message); }
  /// Sets the component; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_component(std::string_view name) noexcept { return set_fixed_str(self().component, name); }
  constexpr std::string_view component_str() const noexcept { return fixed_str_view(self().component); }

  friend constexpr bool operator==(const StatusOps&, const StatusOps&) = default;

 private:
  constexpr Self& self() noexcept { return static_cast<Self&>(*this); }
  constexpr const Self& self() const noexcept { return static_cast<const Self&>(*this); }
  static constexpr std::string_view short_name() noexcept {
    const std::string_view q = reflect::type_name<Self>();
    return q.substr(q.rfind("::") == std::string_view::npos ? 0 : q.rfind("::") + 2);
  }
};
}  // namespace detail

/// General status report of a component: a severity level (a StatusLevel,
/// LEVEL_OK ... LEVEL_FATAL), a component-specific code and a human-readable
/// message. Helpers: create / make / ok / warn / error / fatal, with_component,
/// level_enum / set_level, set_message / message_str, set_component /
/// component_str (see detail::StatusOps).
struct Status : detail::StatusOps<Status> {
  std::uint8_t level{};                ///< a StatusLevel (LEVEL_OK ... LEVEL_FATAL)
  std::uint32_t code{};                ///< status code, component-specific (0 for OK)
  std::array<char, 128> message{};     ///< NUL-terminated, at most 127 characters
  std::array<char, 32> component{};    ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  friend constexpr bool operator==(const Status&, const Status&) = default;
};
HORUS_REFLECT(Status, level, code, message, component, timestamp_ns)

/// HORUS's newer name for Status (horus_types renamed Status to
/// DiagnosticStatus without changing it): the same fields, layout (176 bytes)
/// and helpers. It is a distinct C++ type with its own type name and hash, so
/// the publishers and subscribers of one topic must agree on which one they use.
struct DiagnosticStatus : detail::StatusOps<DiagnosticStatus> {
  std::uint8_t level{};                ///< a StatusLevel (LEVEL_OK ... LEVEL_FATAL)
  std::uint32_t code{};                ///< status code, component-specific (0 for OK)
  std::array<char, 128> message{};     ///< NUL-terminated, at most 127 characters
  std::array<char, 32> component{};    ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  friend constexpr bool operator==(const DiagnosticStatus&, const DiagnosticStatus&) = default;
};
HORUS_REFLECT(DiagnosticStatus, level, code, message, component, timestamp_ns)

// ---------------------------------------------------------------------------
/// Emergency stop signal: engaged = 1 stops all motion; a release (engaged = 0)
/// clears it. auto_reset = 1 allows an automatic restart once the cause clears.
struct EmergencyStop {
  std::uint8_t engaged{};           ///< 1 = stop engaged
  std::array<char, 64> reason{};    ///< NUL-terminated, at most 63 characters
  std::array<char, 32> source{};    ///< NUL-terminated, at most 31 characters
  std::uint8_t auto_reset{};        ///< 1 = auto-reset allowed after clearing
  std::uint64_t timestamp_ns{};

  /// An engaged stop with the reason (auto_reset 0, timestamp 0). Never fails:
  /// a stop must go out whatever its text. A reason that does not fit (more
  /// than 63 characters, or a NUL) is stored shortened to 60 bytes or fewer
  /// plus "...", so the cut is visible; set_reason() is the strict form.
  static constexpr EmergencyStop engage(std::string_view why) noexcept {
    EmergencyStop e{};
    e.engaged = 1;
    detail::diag_set_text_marked(e.reason, why);
    return e;
  }
  /// A release signal: engaged 0, no reason, no source.
  static constexpr EmergencyStop release() noexcept { return EmergencyStop{}; }

  /// A copy with the source set. Never fails, like engage(): a source that
  /// does not fit (more than 31 characters, or a NUL) is shortened with "...".
  [[nodiscard]] constexpr EmergencyStop with_source(std::string_view name) const noexcept {
    EmergencyStop e = *this;
    detail::diag_set_text_marked(e.source, name);
    return e;
  }

  constexpr bool is_engaged() const noexcept { return engaged != 0; }

  /// Sets the reason; returns false, changing nothing, when it does not fit (63 characters at most, no NUL).
  constexpr bool set_reason(std::string_view why) noexcept { return set_fixed_str(reason, why); }
  constexpr std::string_view reason_str() const noexcept { return fixed_str_view(reason); }
  /// Sets the source; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_source(std::string_view name) noexcept { return set_fixed_str(source, name); }
  constexpr std::string_view source_str() const noexcept { return fixed_str_view(source); }

  friend constexpr bool operator==(const EmergencyStop&, const EmergencyStop&) = default;
};
HORUS_REFLECT(EmergencyStop, engaged, reason, source, auto_reset, timestamp_ns)

// ---------------------------------------------------------------------------
/// State of the safety system. The u8 flags are 1 = true, 0 = false.
struct SafetyStatus {
  static constexpr std::uint8_t MODE_NORMAL = 0;
  static constexpr std::uint8_t MODE_REDUCED = 1;
  static constexpr std::uint8_t MODE_SAFE_STOP = 2;

  std::uint8_t enabled{};        ///< safety system active
  std::uint8_t estop_engaged{};  ///< emergency stop engaged
  std::uint8_t watchdog_ok{};
  std::uint8_t limits_ok{};      ///< all limits within bounds
  std::uint8_t comms_ok{};
  std::uint8_t mode{};           ///< MODE_NORMAL, MODE_REDUCED or MODE_SAFE_STOP
  std::uint32_t fault_code{};    ///< 0 = no fault
  std::uint64_t timestamp_ns{};

  /// HORUS's SafetyStatus::new(): enabled, watchdog, limits and comms OK, no
  /// e-stop, MODE_NORMAL, no fault (so is_safe()). SafetyStatus{} is all zeros,
  /// which is not safe (disabled).
  static constexpr SafetyStatus make() noexcept {
    SafetyStatus s{};
    s.enabled = 1;
    s.watchdog_ok = 1;
    s.limits_ok = 1;
    s.comms_ok = 1;
    s.mode = MODE_NORMAL;
    return s;
  }

  /// Safe to operate: enabled, no e-stop, watchdog, limits and comms OK, and no
  /// fault code. (mode is not consulted, as in HORUS.)
  constexpr bool is_safe() const noexcept {
    return enabled != 0 && estop_engaged == 0 && watchdog_ok != 0 && limits_ok != 0 && comms_ok != 0 &&
           fault_code == 0;
  }

  /// Records a fault; a non-zero code also switches to MODE_SAFE_STOP. Code 0
  /// clears the code only (the mode is kept; use clear_faults()).
  constexpr void set_fault(std::uint32_t code) noexcept {
    fault_code = code;
    if (code != 0) mode = MODE_SAFE_STOP;
  }
  /// Clears the fault code and returns to MODE_NORMAL.
  constexpr void clear_faults() noexcept {
    fault_code = 0;
    mode = MODE_NORMAL;
  }

  friend constexpr bool operator==(const SafetyStatus&, const SafetyStatus&) = default;
};
HORUS_REFLECT(SafetyStatus, enabled, estop_engaged, watchdog_ok, limits_ok, comms_ok, mode, fault_code, timestamp_ns)

// ---------------------------------------------------------------------------
/// CPU, memory, disk, network and temperature of a host or process. Field
/// order as HORUS (the spec's table groups them).
struct ResourceUsage {
  float cpu_percent{};               ///< %, 0-100
  std::uint64_t memory_bytes{};      ///< bytes in use
  float memory_percent{};            ///< %, 0-100
  std::uint64_t disk_bytes{};        ///< bytes in use
  float disk_percent{};              ///< %, 0-100
  std::uint64_t network_tx_bytes{};  ///< bytes sent
  std::uint64_t network_rx_bytes{};  ///< bytes received
  float temperature{};               ///< degrees Celsius
  std::uint32_t thread_count{};
  std::uint64_t timestamp_ns{};

  /// HORUS's ResourceUsage::new(): all zeros (stamp timestamp_ns yourself).
  static constexpr ResourceUsage make() noexcept { return ResourceUsage{}; }

  /// cpu_percent > threshold (%). False when either is NaN.
  constexpr bool is_cpu_high(float threshold_percent) const noexcept { return cpu_percent > threshold_percent; }
  /// memory_percent > threshold (%). False when either is NaN.
  constexpr bool is_memory_high(float threshold_percent) const noexcept {
    return memory_percent > threshold_percent;
  }
  /// temperature > threshold (degrees Celsius). False when either is NaN.
  constexpr bool is_temperature_high(float threshold_celsius) const noexcept {
    return temperature > threshold_celsius;
  }

  friend constexpr bool operator==(const ResourceUsage&, const ResourceUsage&) = default;
};
HORUS_REFLECT(ResourceUsage, cpu_percent, memory_bytes, memory_percent, disk_bytes, disk_percent, network_tx_bytes,
              network_rx_bytes, temperature, thread_count, timestamp_ns)

// ---------------------------------------------------------------------------
/// One key-value diagnostic. The value is text; value_type says how to read it
/// (TYPE_STRING, TYPE_INT, TYPE_FLOAT or TYPE_BOOL).
struct DiagnosticValue {
  static constexpr std::uint8_t TYPE_STRING = 0;
  static constexpr std::uint8_t TYPE_INT = 1;
  static constexpr std::uint8_t TYPE_FLOAT = 2;
  static constexpr std::uint8_t TYPE_BOOL = 3;

  std::array<char, 32> key{};    ///< NUL-terminated, at most 31 characters
  std::array<char, 64> value{};  ///< NUL-terminated text, at most 63 characters
  std::uint8_t value_type{};     ///< TYPE_STRING, TYPE_INT, TYPE_FLOAT or TYPE_BOOL

  /// A text value (HORUS's DiagnosticValue::string), or nullopt when the key
  /// (31 characters at most) or the value (63 at most) does not fit or has a NUL.
  static constexpr std::optional<DiagnosticValue> from_string(std::string_view k, std::string_view v) noexcept {
    return with_type(k, v, TYPE_STRING);
  }
  /// An integer value in decimal (HORUS's DiagnosticValue::int), or nullopt when the key does not fit.
  static std::optional<DiagnosticValue> from_int(std::string_view k, std::int64_t v) {
    return with_type(k, std::to_string(v), TYPE_INT);
  }
  /// A float value with 3 decimals, "1.500" (HORUS's DiagnosticValue::float,
  /// Rust's {:.3}; NaN is "NaN", infinities "inf" and "-inf"), or nullopt when
  /// the key does not fit or the text is over 63 characters (|v| >= 1e59).
  static std::optional<DiagnosticValue> from_float(std::string_view k, double v);
  /// "true" or "false" (HORUS's DiagnosticValue::bool), or nullopt when the key does not fit.
  static constexpr std::optional<DiagnosticValue> from_bool(std::string_view k, bool v) noexcept {
    return with_type(k, v ? "true" : "false", TYPE_BOOL);
  }

  constexpr std::string_view key_str() const noexcept { return fixed_str_view(key); }
  constexpr std::string_view value_str() const noexcept { return fixed_str_view(value); }

  /// The value as an integer when value_type is TYPE_INT and the text is a
  /// whole decimal i64; else nullopt.
  std::optional<std::int64_t> as_int() const noexcept {
    if (value_type != TYPE_INT) return std::nullopt;
    const std::string_view t = value_str();
    std::int64_t out{};
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), out);
    if (ec != std::errc{} || end != t.data() + t.size()) return std::nullopt;
    return out;
  }
  /// The value as a number when value_type is TYPE_FLOAT (or TYPE_INT) and the
  /// whole text parses ("NaN" and "inf" included); else nullopt.
  std::optional<double> as_float() const noexcept {
    if (value_type != TYPE_FLOAT && value_type != TYPE_INT) return std::nullopt;
    const std::string_view t = value_str();
    double out{};
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), out);
    if (ec != std::errc{} || end != t.data() + t.size()) return std::nullopt;
    return out;
  }
  /// The value as a bool when value_type is TYPE_BOOL and the text is "true" or "false"; else nullopt.
  constexpr std::optional<bool> as_bool() const noexcept {
    if (value_type != TYPE_BOOL) return std::nullopt;
    if (value_str() == "true") return true;
    if (value_str() == "false") return false;
    return std::nullopt;
  }

  friend constexpr bool operator==(const DiagnosticValue&, const DiagnosticValue&) = default;

 private:
  static constexpr std::optional<DiagnosticValue> with_type(std::string_view k, std::string_view v,
                                                            std::uint8_t type) noexcept {
    DiagnosticValue d{};
    if (!set_fixed_str(d.key, k) || !set_fixed_str(d.value, v)) return std::nullopt;
    d.value_type = type;
    return d;
  }
};
HORUS_REFLECT(DiagnosticValue, key, value, value_type)

// ---------------------------------------------------------------------------
/// Up to 16 key-value diagnostics of one component with an overall level.
/// Entries [0, value_count) are in use.
struct DiagnosticReport {
  static constexpr std::size_t kMaxValues = 16;

  std::array<char, 32> component{};                   ///< NUL-terminated, at most 31 characters
  std::array<DiagnosticValue, kMaxValues> values{};
  std::uint8_t value_count{};                         ///< entries in use, at most 16
  std::uint8_t level{};                               ///< a StatusLevel
  std::uint64_t timestamp_ns{};

  /// An empty report (level Ok) for the component, or nullopt when the name
  /// does not fit (at most 31 characters, no NUL).
  static constexpr std::optional<DiagnosticReport> create(std::string_view name) noexcept {
    DiagnosticReport r{};
    if (!r.set_component(name)) return std::nullopt;
    return r;
  }
  /// Throwing form of create() (HORUS's DiagnosticReport::new): std::invalid_argument when the name does not fit.
  static DiagnosticReport make(std::string_view name) {
    DiagnosticReport r{};
    detail::diag_set_text_or_throw(r.component, name, "DiagnosticReport component");
    return r;
  }

  /// value_count, clamped to kMaxValues (a received message may hold any byte).
  constexpr std::size_t count() const noexcept { return std::min<std::size_t>(value_count, kMaxValues); }
  constexpr bool is_full() const noexcept { return count() >= kMaxValues; }

  /// Appends a value; returns false, changing nothing, when the report already holds 16.
  constexpr bool add_value(const DiagnosticValue& v) noexcept {
    const std::size_t i = count();
    if (i >= kMaxValues) return false;
    values[i] = v;
    value_count = static_cast<std::uint8_t>(i + 1);
    return true;
  }
  /// Appends a text value; false, changing nothing, when full or the key or value does not fit.
  constexpr bool add_string(std::string_view k, std::string_view v) noexcept {
    return add_if(DiagnosticValue::from_string(k, v));
  }
  /// Appends an integer value; false, changing nothing, when full or the key does not fit.
  bool add_int(std::string_view k, std::int64_t v) { return add_if(DiagnosticValue::from_int(k, v)); }
  /// Appends a float value (3 decimals); false, changing nothing, when full or the key or text does not fit.
  bool add_float(std::string_view k, double v) { return add_if(DiagnosticValue::from_float(k, v)); }
  /// Appends a bool value; false, changing nothing, when full or the key does not fit.
  constexpr bool add_bool(std::string_view k, bool v) noexcept { return add_if(DiagnosticValue::from_bool(k, v)); }

  /// The first value with this key among the entries in use, or nullptr.
  constexpr const DiagnosticValue* find(std::string_view k) const noexcept {
    for (std::size_t i = 0; i < count(); ++i)
      if (values[i].key_str() == k) return &values[i];
    return nullptr;
  }

  constexpr StatusLevel level_enum() const noexcept { return static_cast<StatusLevel>(level); }
  constexpr void set_level(StatusLevel lvl) noexcept { level = static_cast<std::uint8_t>(lvl); }

  /// Sets the component; returns false, changing nothing, when it does not fit (31 characters at most, no NUL).
  constexpr bool set_component(std::string_view name) noexcept { return set_fixed_str(component, name); }
  constexpr std::string_view component_str() const noexcept { return fixed_str_view(component); }

  /// "DiagnosticReport(motor_left, Warn, 3 values: temp_c=45.500, rpm=1200, ok=true)".
  /// Lists as many values as fit in about 170 characters, then "+N more": the
  /// line always stays under 200 characters (values over 24 bytes are cut to
  /// at most 24 bytes, at a UTF-8 character boundary, and marked with "...").
  std::string log_summary() const;

  friend constexpr bool operator==(const DiagnosticReport&, const DiagnosticReport&) = default;

 private:
  constexpr bool add_if(const std::optional<DiagnosticValue>& v) noexcept { return v && add_value(*v); }
};
HORUS_REFLECT(DiagnosticReport, component, values, value_count, level, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<NodeHeartbeat>,
              "NodeHeartbeat must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Status>, "Status must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<DiagnosticStatus>,
              "DiagnosticStatus must be trivially copyable and standard layout");
static_assert(sizeof(Status) == 176 && sizeof(DiagnosticStatus) == 176, "Status has HORUS's layout (176 bytes)");
static_assert(horus::reflect::is_fixed_size<EmergencyStop>,
              "EmergencyStop must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<SafetyStatus>,
              "SafetyStatus must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<ResourceUsage>,
              "ResourceUsage must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<DiagnosticValue>,
              "DiagnosticValue must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<DiagnosticReport>,
              "DiagnosticReport must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(Heartbeat, NodeHeartbeat, Status, DiagnosticStatus, EmergencyStop, SafetyStatus,
                        ResourceUsage, DiagnosticValue, DiagnosticReport)

}  // namespace horus::msg

HORUS_API_END
