// The table of hosts a horus::Fleet keeps (fleet.cpp): what each heartbeat and announcement says
// of its host, when a host is lost (`misses` heartbeat periods without a sign of life, plus one),
// bounded (max_hosts; lost hosts forgotten after forget_after), and the agent's fleet view to
// start from. It neither sends nor calls back: each call returns the events it caused. Not
// thread-safe: Fleet calls it under its mutex.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fleet_internal.hpp"
#include "horus/fleet.hpp"
#include "horus/fleet_messages.hpp"

namespace horus::fleet::detail {

/// An announcement's type signatures by type hash; nullopt when the announcement is malformed
/// (empty host, too many processes, topics or types, a signature that does not hash to its
/// type: corrupt or forged). Pointers into `a`.
std::optional<std::map<std::uint64_t, const std::string*>> announced_signatures(const Announcement& a);

class HostTable {
 public:
  using Clock = std::chrono::steady_clock;
  struct Limits {
    std::uint64_t self = 0;  // this host's id
    std::uint32_t misses = 3;
    std::size_t max_hosts = 1024;
    std::chrono::nanoseconds forget_after = std::chrono::hours(1);
  };
  /// What a message did to the table.
  enum class Taken {
    Malformed,  // refused: not a valid message, or no room for a new host (count it)
    Kept,
    Ask,  // kept; the host's announcement is missing or old: ask it again (at most once a second)
  };

  explicit HostTable(Limits limits) : limits_(limits) {}

  /// `now_steady_ns`: steady_ns() when it arrived (the link's round-trip time and clock offset).
  Taken heartbeat(const Heartbeat& h, Clock::time_point now, std::uint64_t now_steady_ns, std::vector<FleetEvent>& events);
  /// `signatures`: announced_signatures(a).
  Taken announce(const Announcement& a, const std::map<std::uint64_t, const std::string*>& signatures,
                 Clock::time_point now, std::vector<FleetEvent>& events);
  /// Marks lost the hosts silent for too long, forgets those lost for forget_after. (The caller
  /// skips it when its periodic check ran late: heartbeats may wait unread; shortest_period.)
  void check(Clock::time_point now, std::vector<FleetEvent>& events);
  /// The shortest heartbeat period of the hosts (100 ms when none says): how late a check may
  /// run before it counts as stalled.
  std::chrono::milliseconds shortest_period() const;
  /// Starts from the fleet view this host's agent published (fleet_messages.hpp): the hosts it
  /// saw, lost ones included, as they were then. Hosts already known are kept as they are.
  void seed(const FleetView& view, Clock::time_point now, std::int64_t now_unix_ns);

  /// Every host (sorted by name, then id), or the one named `name`.
  std::vector<FleetHost> hosts(Clock::time_point now) const;
  std::optional<FleetHost> host(std::string_view name, Clock::time_point now) const;

 private:
  struct Record {
    FleetHost host;
    LinkStats link;
    Clock::time_point last_seen{};
    std::uint64_t version_have = 0;    // of the announcement we hold
    std::uint64_t version_wanted = 0;  // the latest heartbeat's
    Clock::time_point last_request{};
  };
  static std::int64_t lost_since_ns(const Record& r) { return r.host.lost_since_unix_ms * 1'000'000; }
  // A sign of life from `id`: a new host joins (nullptr when max_hosts hosts live), a lost one
  // rejoins.
  Record* seen(std::uint64_t id, const std::string& name, Clock::time_point now, std::vector<FleetEvent>& events);
  static FleetHost snapshot(const Record& r, Clock::time_point now);

  Limits limits_;
  std::map<std::uint64_t, Record> hosts_;
};

}  // namespace horus::fleet::detail
