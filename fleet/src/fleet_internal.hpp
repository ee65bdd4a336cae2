// What the fleet agent (agent.cpp), the bridges (bridge.cpp) and horus::Fleet (fleet.cpp) share: how the fleet
// layer's topics are opened, and this host's identity.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "horus/backend.hpp"
#include "horus/topic_options.hpp"
#include "horus/error.hpp"
#include "horus/fleet_messages.hpp"
#include "horus/settings.hpp"
#include "horus/transport_registry.hpp"

namespace horus::fleet::detail {

/// The prefix of the fleet layer's own topics (they do not keep the host announced).
inline constexpr std::string_view kFleetTopicPrefix = net::TransportInfo::kControlTopicPrefix;

/// Keeps this host announced on a transport while held: the agent of that transport runs in this
/// process while one is (agent.cpp). A bridge of a fleet topic holds one, and so does a Fleet.
using Presence = std::shared_ptr<void>;
/// `settings`: the opening operation's; the agent it starts takes its own from them.
Presence acquire_presence(const std::string& transport, const Settings& settings);

/// Whether `value` (of HORUS_BRIDGE) lets this process bridge fleet topics (0: never; 1 or
/// empty: it may); a process that may not neither bridges nor announces its host (bridge.cpp).
Result<bool> may_bridge(std::string_view value);


/// The fleet layer's topics on `transport`: heartbeats best effort, announcements and requests
/// reliable; the slot sizes bound what a host can announce.
inline constexpr std::size_t kHeartbeatBytes = 16 * 1024;
inline constexpr std::size_t kAnnouncementBytes = 256 * 1024;
TopicOptions heartbeat_options(const std::string& transport);
TopicOptions announce_options(const std::string& transport);
TopicOptions request_options(const std::string& transport);

/// Nanoseconds of the steady clock (what heartbeats carry and echo).
std::uint64_t steady_ns() noexcept;
/// Nanoseconds of the realtime clock (Unix time).
std::int64_t unix_ns() noexcept;

/// The host topic of the fleet view (horus.fleet.view.<transport>) and its options.
std::string view_topic(const std::string& transport);
TopicOptions view_options();
inline constexpr std::size_t kViewBytes = 64 * 1024;
inline constexpr std::size_t kViewHosts = 256;  // at most this many hosts in a view

/// What an announcement may list (more is refused as malformed): processes, topics, types.
inline constexpr std::size_t kMaxAnnouncedProcesses = 4096;
inline constexpr std::size_t kMaxAnnouncedTopics = 16384;

/// Forgets the hosts of `hosts` (a map by id) lost for longer than `forget_after`;
/// `lost_since(record)` is when one was lost (Unix ns, 0: it is not lost). The ids forgotten go
/// to `forgotten` when it is given.
template <class Map, class LostSince>
void forget_lost(Map& hosts, std::chrono::nanoseconds forget_after, std::int64_t now_unix_ns, LostSince lost_since,
                 std::vector<std::uint64_t>* forgotten = nullptr) {
  for (auto it = hosts.begin(); it != hosts.end();) {
    const std::int64_t since = lost_since(it->second);
    if (since != 0 && now_unix_ns - since > forget_after.count()) {
      if (forgotten != nullptr) forgotten->push_back(it->first);
      it = hosts.erase(it);
    } else {
      ++it;
    }
  }
}

/// Makes room for one more host in `hosts` when it holds `max` already: forgets the host lost
/// longest ago (its id goes to `forgotten`). False when every host is alive: the newcomer is
/// refused (a flood of forged host ids cannot push out the hosts that live).
template <class Map, class LostSince>
bool make_room(Map& hosts, std::size_t max, LostSince lost_since, std::vector<std::uint64_t>* forgotten = nullptr) {
  if (hosts.size() < max) return true;
  auto oldest = hosts.end();
  std::int64_t when = INT64_MAX;
  for (auto it = hosts.begin(); it != hosts.end(); ++it)
    if (const std::int64_t since = lost_since(it->second); since != 0 && since < when) {
      when = since;
      oldest = it;
    }
  if (oldest == hosts.end()) return false;
  if (forgotten != nullptr) forgotten->push_back(oldest->first);
  hosts.erase(oldest);
  return true;
}

/// The link to one host, from its heartbeats: round trip (from our heartbeat that it echoes),
/// loss (gaps in its sequence numbers over the last kLossWindow), and the offset of its
/// realtime clock against ours, NTP-style: offset = its send time + RTT/2 - our receive time,
/// uncertain by RTT/2; of the last kOffsetSamples, the one with the shortest round trip (the
/// least queueing) is kept.
class LinkStats {
 public:
  static constexpr std::chrono::seconds kLossWindow{10};
  static constexpr std::size_t kOffsetSamples = 8;

  /// A heartbeat from the host arrived now; `self` is our host id.
  void on_heartbeat(const Heartbeat& h, std::uint64_t self, std::uint64_t now_steady_ns, std::int64_t now_unix_ns);
  std::int64_t rtt_ns() const noexcept { return rtt_ns_; }  // -1: not known
  /// The fraction of its heartbeats lost over the window; -1 until 10 arrived.
  double loss() const noexcept;
  /// How long the loss window spans now (its first to its last heartbeat).
  std::chrono::nanoseconds span() const noexcept {
    return std::chrono::nanoseconds(got_.size() < 2 ? 0 : got_.back().at_ns - got_.front().at_ns);
  }
  std::int64_t offset_ns() const noexcept { return offset_ns_; }
  std::int64_t uncertainty_ns() const noexcept { return uncertainty_ns_; }  // -1: no offset

 private:
  struct Got {
    std::uint64_t seq;
    std::uint64_t at_ns;
  };
  std::vector<Got> got_;  // within the window, oldest first
  std::int64_t rtt_ns_ = -1;
  struct Sample {
    std::int64_t rtt_ns, offset_ns;
  };
  std::vector<Sample> samples_;  // the last kOffsetSamples
  std::int64_t offset_ns_ = 0;
  std::int64_t uncertainty_ns_ = -1;
};

}  // namespace horus::fleet::detail
