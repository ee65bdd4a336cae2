// Where a topic's messages go: a scope, and for fleet topics a network transport by name.
//
//   scope     what it reaches                                   HORUS_BACKEND
//   process   an in-process ring: handles of this process only   inproc
//   host      a POSIX shared-memory ring: every process of this   shm (the default; auto)
//             host (and HORUS_NAMESPACE) opening the name
//   fleet     a network transport: other processes and hosts;     cyclonedds, fastdds, lcm, or the
//             handles of this process share an in-process ring    name of any registered transport
//
// Transports register themselves by name (horus/transport_registry.hpp); api/ knows none of
// them. horus::Backend names a choice on both axes; its constants keep the names horus has
// always had (Backend::SharedMemory, Backend::CycloneDds, ...).
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "horus/error.hpp"
#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// How far a topic's messages go.
enum class Scope : std::uint8_t { Process, Host, Fleet };
/// "process", "host", "fleet".
std::string_view to_string(Scope s) noexcept;

/// A scope and, for Scope::Fleet, the name of a registered network transport.
class Backend {
 public:
  /// Shared memory (the default).
  constexpr Backend() noexcept = default;
  /// A fleet topic over the transport registered as `transport` ("cyclonedds", "lcm", ...).
  /// The name must outlive the Backend (a literal, or a name the registry returned).
  static constexpr Backend network(std::string_view transport) noexcept { return Backend(Scope::Fleet, transport); }

  static const Backend InProcess;     // Scope::Process (HORUS_BACKEND=inproc)
  static const Backend SharedMemory;  // Scope::Host (HORUS_BACKEND=shm, auto, unset)
  static const Backend CycloneDds;    // Cyclone DDS over UDP (HORUS_BACKEND=cyclonedds)
  static const Backend FastDds;       // Fast DDS over UDP (HORUS_BACKEND=fastdds); both speak DDSI-RTPS
                                      // and XCDR1, so a Cyclone DDS process and a Fast DDS one talk
  static const Backend Lcm;           // LCM over UDP multicast (HORUS_BACKEND=lcm; HORUS_LCM_URL):
                                      // channel = topic name, lcm-gen compatible encoding

  constexpr Scope scope() const noexcept { return scope_; }
  /// The transport's registry name for a fleet topic; empty otherwise.
  constexpr std::string_view transport() const noexcept { return transport_; }
  constexpr bool operator==(const Backend& o) const noexcept {
    return scope_ == o.scope_ && transport_ == o.transport_;
  }

 private:
  constexpr Backend(Scope s, std::string_view t) noexcept : scope_(s), transport_(t) {}
  Scope scope_ = Scope::Host;
  std::string_view transport_;
};

inline constexpr Backend Backend::InProcess{Scope::Process, {}};
inline constexpr Backend Backend::SharedMemory{Scope::Host, {}};
inline constexpr Backend Backend::CycloneDds = Backend::network("cyclonedds");
inline constexpr Backend Backend::FastDds = Backend::network("fastdds");
inline constexpr Backend Backend::Lcm = Backend::network("lcm");

/// "inproc", "shm", or the transport's name ("cyclonedds", "fastdds", "lcm"): HORUS_BACKEND's values.
std::string_view to_string(const Backend& b) noexcept;

/// True for the backends that reach other hosts (Scope::Fleet).
constexpr bool is_network(const Backend& b) noexcept { return b.scope() == Scope::Fleet; }

/// True when this program can use backend b: always for process and host; for a fleet topic,
/// when its transport is registered (built into horus and linked through horus::horus).
bool backend_available(const Backend& b) noexcept;

/// A fleet topic's share of the host's link (the file's network.max_bandwidth): the host's
/// bridges serve High first, then Normal, then Low (horus/backend.hpp, TopicOptions::priority).
enum class Priority : std::uint8_t { Low, Normal, High };
/// "low", "normal", "high".
std::string_view to_string(Priority p) noexcept;

/// The level of a verbose topic's lines in the library's log (TopicOptions::log_level); the
/// values are spdlog's, so HORUS_LOG_LEVEL above it hides them.
enum class LogLevel : std::uint8_t { Trace, Debug, Info, Warn, Error };
/// "trace", "debug", "info", "warn", "error".
std::string_view to_string(LogLevel l) noexcept;
/// The level named `name` (one of to_string's); nothing for another word.
std::optional<LogLevel> log_level_from(std::string_view name) noexcept;
/// Lines a verbose topic logs per second in a process at most, unless log_rate_hz says otherwise.
inline constexpr double kDefaultLogRateHz = 5.0;

/// Per-topic choices made in code (they take precedence over the environment).
struct TopicOptions {
  std::optional<Backend> backend;         // default: HORUS_BACKEND, else shared memory
  std::optional<std::uint32_t> capacity;  // slots per publisher, a power of two
  std::optional<std::size_t> slot_size;   // serialized messages: the largest encoded message;
                                          // large data: the largest message's bytes (pool slot)
  // Network backends only (the defaults come from net::default_qos<T>, horus/qos.hpp):
  std::optional<net::Reliability> reliability = std::nullopt;
  std::optional<net::Durability> durability = std::nullopt;
  // Fleet topics: the host's egress budget. The bridge sends at most `max_rate_hz` messages a
  // second and `max_bandwidth` bytes a second (a token bucket) to the network; when over budget
  // the newest message waits for its turn and older ones are not sent (counted per topic:
  // `horus topic info`, "budget dropped"). Local handles are not affected.
  std::optional<double> max_rate_hz = std::nullopt;
  std::optional<std::uint64_t> max_bandwidth = std::nullopt;  // bytes per second
  // Fleet topics: the topic's share of the host's link budget (network.max_bandwidth in the
  // file, shared by every process of the host). High always goes (and uses the link); Normal
  // goes while what the host sent stays within 50 ms of the link's rate; Low within 10 ms, so
  // that it leaves the link's last bytes to the others. What waits is the newest message
  // (counted as budget dropped when a newer one replaces it). Default Normal; the fleet's own
  // heartbeats and announcements are High.
  std::optional<Priority> priority = std::nullopt;
  // Every backend (mapped to the DDS QoS of the same name on DDS, enforced by the handle
  // everywhere; horus/topic.hpp):
  // - deadline: the period a topic's messages must keep. A receiving handle counts each full
  //   period without a message (the requested deadline: a watchdog on cmd_vel), a sending one
  //   each full period between its own sends (the offered deadline): deadline_missed_count(),
  //   and Executor::on_deadline_missed calls back at once.
  // - lifespan: a message whose timestamp_ns (Unix ns, as the publisher set it) is older than
  //   this on receipt is not delivered; counted in expired_count() and dropped_count().
  //   Messages without a timestamp_ns (or with 0) never expire.
  std::optional<std::chrono::nanoseconds> deadline = std::nullopt;
  std::optional<std::chrono::nanoseconds> lifespan = std::nullopt;
  // Traffic logging (off by default): each send and receive of the handle logs a line through
  // the library's logger: the direction, the topic, the handle's count (send #N, recv #N), the
  // drops so far and the message's horus::log_summary() (large data: its description, never its
  // bytes). At `log_level` (default info), at most `log_rate_hz` lines per second for the topic
  // in this process (default kDefaultLogRateHz; 0: every message); the next line logged says how
  // many were held back. Also `log: true` on a rule of the configuration file, or
  // HORUS_LOG_TOPICS=PATTERN[,PATTERN...] (`!PATTERN` turns logging off).
  std::optional<bool> verbose = std::nullopt;
  std::optional<LogLevel> log_level = std::nullopt;
  std::optional<double> log_rate_hz = std::nullopt;
};

/// The backend HORUS_BACKEND selects (auto|shm|inproc, or a registered transport's name:
/// cyclonedds|fastdds|lcm; unset means auto = shm); an error names a bad value and lists the
/// valid ones.
Result<Backend> backend_from_environment();
/// The backend that `value` (of HORUS_BACKEND) selects; empty: auto.
Result<Backend> backend_from(std::string_view value);

/// The name a fleet topic has on its transport (a DDS topic name "horus/fleet/robot_1/pose", an
/// LCM channel "fleet.robot_1.pose"), by the transport's own rule; the topic name itself for
/// process and host topics. Errc::InvalidName names the rule a name breaks; Errc::Config a
/// transport this program does not have.
Result<std::string> wire_name(const Backend& b, std::string_view topic);

}  // namespace horus

HORUS_API_END
