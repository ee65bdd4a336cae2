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
