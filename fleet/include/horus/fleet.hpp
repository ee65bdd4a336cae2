// horus::Fleet: the hosts of the fleet, whether each is alive, and what runs on it.
//
//   auto fleet = horus::Fleet::open();                 // its own thread; or open(executor)
//   fleet.value()->on_change([](const horus::FleetEvent& e) {
//     if (e.kind == horus::FleetEvent::Kind::Lost && e.host.name == "operator") stop_robot();
//   });
//   for (const auto& h : fleet.value()->hosts()) fmt::print("{} {}\n", h.name, horus::to_string(h.state));
//
// How it works (no daemon): every process that has a fleet topic open (or a Fleet) runs a small
// agent for that network backend; on each host the agent of the process that holds the host's
// bridge of horus.fleet.heartbeat publishes a heartbeat every period (100 ms by default;
// HORUS_FLEET_HEARTBEAT_MS, or `fleet.heartbeat_ms` in the configuration file) and an
// announcement (the host's horus processes, its topics with their types' signatures) every
// 2 s, at once when they change and when asked (a newcomer asks). These are ordinary fleet
// topics (horus/fleet_messages.hpp). A Fleet reads them: a host is *lost* when
// `misses` (3) of its heartbeats in a row did not come (its own period, plus one period of
// tolerance), and *rejoined* when heartbeats come again. A host's own processes see it too
// (self = true). Hosts on another DDS domain or LCM URL are never seen (another network).
// Announcements that do not decode, or whose content is inconsistent (a type signature that
// does not hash to its type, a host without an id), are ignored and counted in malformed().
// The agent of the process that speaks for a host keeps the fleet's state (the fleet view, a
// host topic): a Fleet opened later starts from it, hosts lost earlier included.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

class Executor;

enum class HostState : std::uint8_t { Alive, Lost, Rejoined };
/// "alive", "lost", "rejoined".
std::string_view to_string(HostState s) noexcept;

struct FleetProcess {
  std::uint32_t pid = 0;
  std::string name;
  std::uint64_t start_unix_ns = 0;
};

struct FleetTopic {
  std::string name;
  std::string type_name;
  std::uint64_t type_hash = 0;
  std::string scope;      // "host" or "fleet"
  std::string transport;  // fleet topics: the network backend
  std::uint32_t publishers = 0;
  std::uint32_t subscribers = 0;
  double rate_hz = -1;    // -1: not known yet
  std::uint64_t messages = 0;
  std::uint64_t dropped = 0;
  std::uint32_t message_size = 0;
  std::string signature;  // the type's layout text (empty: not announced); decodes it without the type
};

struct FleetHost {
  std::uint64_t id = 0;
  std::string name;
  std::string shm_namespace;
  HostState state = HostState::Alive;
  bool self = false;                        // the host this process runs on
  std::chrono::milliseconds heartbeat_age{0};  // since its last heartbeat arrived
  std::chrono::milliseconds period{0};         // its heartbeat period
  std::optional<std::chrono::microseconds> rtt;  // the link's round trip (through both hosts' bridges)
  double loss = -1;  // the fraction of its heartbeats lost over the last 10 s (-1: not known yet)
  /// Its realtime clock minus ours, NTP-style from the heartbeats' echoes (its send time + RTT/2
  /// - our receive time), and how uncertain that is (half the round trip of the sample used).
  std::optional<std::chrono::microseconds> clock_offset;
  std::optional<std::chrono::microseconds> clock_uncertainty;
  std::int64_t last_seen_unix_ms = 0;   // its last heartbeat, Unix time
  std::int64_t lost_since_unix_ms = 0;  // when it was lost (0: it is not)
  std::uint32_t rejoins = 0;
  std::uint64_t heartbeats = 0;  // received
  bool announced = false;        // its announcement arrived (processes and topics are known)
  std::vector<FleetProcess> processes;
  std::vector<FleetTopic> topics;
};

struct FleetEvent {
  enum class Kind : std::uint8_t { Joined, Lost, Rejoined, Changed };
  Kind kind = Kind::Joined;
  FleetHost host;  // as it is after the event
};
/// "joined", "lost", "rejoined", "changed".
std::string_view to_string(FleetEvent::Kind k) noexcept;

struct FleetOptions {
  /// The network backend to watch ("cyclonedds", "fastdds", "lcm"); default: HORUS_BACKEND's
  /// when it names one, else the configuration file's network.backend.
  std::optional<std::string> transport;
  /// Heartbeats a host may miss before it is lost; default: the file's fleet.misses, else 3.
  std::optional<std::uint32_t> misses;
};

class Fleet {
 public:
  /// Watches the fleet on a thread of its own: on_change callbacks run on it.
  static Result<std::unique_ptr<Fleet>> open(FleetOptions options = {});
  /// Watches the fleet through `executor`: on_change callbacks run on the thread that spins it.
  /// The executor must outlive the Fleet.
  static Result<std::unique_ptr<Fleet>> open(Executor& executor, FleetOptions options = {});
  ~Fleet();
  Fleet(const Fleet&) = delete;
  Fleet& operator=(const Fleet&) = delete;

  /// Every host seen, by name. Thread-safe.
  std::vector<FleetHost> hosts() const;
  std::optional<FleetHost> host(std::string_view name) const;
  /// This host's id.
  std::uint64_t self_id() const noexcept;
  const std::string& transport() const noexcept;

  using CallbackId = std::uint64_t;
  /// Calls `callback` for each host that joins, is lost, rejoins, or announces a change.
  CallbackId on_change(std::function<void(const FleetEvent&)> callback);
  bool remove(CallbackId id);

  /// Asks every host to announce itself now (open() does it once).
  void refresh();
  /// Heartbeats and announcements ignored: not decodable (counted by the host's bridge) or
  /// inconsistent (counted here).
  std::uint64_t malformed() const;

  struct State;

 private:
  explicit Fleet(std::shared_ptr<State> state) : state_(std::move(state)) {}
  std::shared_ptr<State> state_;
};

namespace fleet {
/// This host's id and name as the fleet layer announces them (hostname, boot, shared-memory
/// domain and namespace).
std::uint64_t host_id();
std::string host_name();
/// This host's realtime clock (Unix ns) as its heartbeats carry it: the clock that
/// FleetHost::clock_offset compares (shifted by HORUS_TEST_CLOCK_OFFSET_MS in tests).
std::int64_t host_clock_unix_ns() noexcept;
/// Installs the fleet layer in api/ (the composition root horus::horus calls it before main()).
void install();
}  // namespace fleet

}  // namespace horus

HORUS_API_END
