// The fleet layer's own messages, on three fleet topics of the host's network backend:
//
//   horus.fleet.heartbeat  Heartbeat      every period (100 ms), best effort: "this host lives"
//   horus.fleet.announce   Announcement   every 2 s, at once on change and on request, reliable:
//                                         its processes, its topics and their types' signatures
//   horus.fleet.request    Request        reliable: "announce yourself now" (a newcomer, a tool)
//
// They are ordinary horus topics: any horus program may read them (Topic<Heartbeat>), any DDS
// or LCM program may too (DDS types horus::fleet::Heartbeat ..., LCM channels
// horus/fleet/heartbeat ...). One process per host publishes them: the one that holds the
// host's bridge of horus.fleet.heartbeat (the same election as every fleet topic's bridge).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "horus/reflect.hpp"
#include "horus/transport_registry.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::fleet {

inline constexpr const char* kHeartbeatTopic = "horus.fleet.heartbeat";
inline constexpr const char* kAnnounceTopic = "horus.fleet.announce";
inline constexpr const char* kRequestTopic = "horus.fleet.request";

/// Whether `topic` is one of the fleet layer's own (the three above, and the host view
/// horus.fleet.view.<transport>): they travel on a transport's control instance, and the CLI's
/// lists, recordings and live views leave them out unless asked.
inline bool is_fleet_layer_topic(std::string_view topic) noexcept {
  return topic.starts_with(net::TransportInfo::kControlTopicPrefix);
}

/// What one host last heard from another: its heartbeat's send time (the other host's steady
/// clock) and how long ago. The other host subtracts both from its clock: the link's RTT.
struct HeartbeatEcho {
  std::uint64_t host_id{};
  std::uint64_t sent_ns{};
  std::uint64_t held_ns{};
};
HORUS_REFLECT(HeartbeatEcho, host_id, sent_ns, held_ns)

struct Heartbeat {
  std::uint64_t host_id{};  // this host's identity (hostname, boot, shared-memory domain)
  std::string host;         // its name
  std::uint64_t seq{};
  std::uint64_t sent_ns{};  // the sender's steady clock (only the sender compares it)
  std::int64_t sent_unix_ns{};  // the sender's realtime clock: with an echo, the clocks' offset (NTP-style)
  std::uint32_t period_ms{};
  std::uint64_t announce_version{};  // the content of the host's latest announcement
  std::uint32_t processes{};
  std::uint32_t topics{};
  std::vector<HeartbeatEcho> echoes;  // the other hosts heard lately
};
HORUS_REFLECT(Heartbeat, host_id, host, seq, sent_ns, sent_unix_ns, period_ms, announce_version, processes, topics,
              echoes)

/// A host as this host's agent last saw it. The agent of the process that speaks for the host
/// keeps the fleet's state and publishes it on the host topic horus.fleet.view.<transport>
/// (shared memory only): a process or tool that starts later reads it at once (read_latest),
/// lost hosts included, instead of waiting for a discovery round.
struct ViewedHost {
  std::uint64_t host_id{};
  std::string host;
  std::uint32_t state{};  // horus::HostState: 0 alive, 1 lost, 2 rejoined
  std::uint32_t period_ms{};
  std::uint64_t heartbeats{};
  std::uint32_t rejoins{};
  std::int64_t first_seen_unix_ns{};
  std::int64_t last_seen_unix_ns{};
  std::int64_t lost_since_unix_ns{};  // 0: not lost
  std::int64_t rtt_ns{-1};            // -1: not known
  double loss{-1};                    // its heartbeats lost over the window (-1: not known)
  std::int64_t clock_offset_ns{};     // its realtime clock minus ours
  std::int64_t clock_uncertainty_ns{-1};  // -1: the offset is not known
};
HORUS_REFLECT(ViewedHost, host_id, host, state, period_ms, heartbeats, rejoins, first_seen_unix_ns, last_seen_unix_ns,
              lost_since_unix_ns, rtt_ns, loss, clock_offset_ns, clock_uncertainty_ns)

struct FleetView {
  std::uint64_t host_id{};  // the host whose agent made it
  std::uint64_t version{};
  std::int64_t made_unix_ns{};
  std::vector<ViewedHost> hosts;  // the other hosts
};
HORUS_REFLECT(FleetView, host_id, version, made_unix_ns, hosts)

struct AnnouncedProcess {
  std::uint32_t pid{};
  std::string name;
  std::uint64_t start_unix_ns{};
};
HORUS_REFLECT(AnnouncedProcess, pid, name, start_unix_ns)

struct AnnouncedTopic {
  std::string name;
  std::string type_name;
  std::uint64_t type_hash{};
  std::string scope;      // "host" or "fleet"
  std::string transport;  // fleet: "cyclonedds", "fastdds", "lcm"
  std::uint32_t publishers{};
  std::uint32_t subscribers{};
  double rate_hz{};       // messages per second since the previous announcement (-1: not known yet)
  std::uint64_t messages{};
  std::uint64_t dropped{};
  std::uint32_t message_size{};  // bytes (fixed-size) or the largest encoded message
};
HORUS_REFLECT(AnnouncedTopic, name, type_name, type_hash, scope, transport, publishers, subscribers, rate_hz,
              messages, dropped, message_size)

/// A type's signature (reflect::type_signature): its FNV-1a hash is the type hash, so a
/// receiver checks it; a tool decodes the type's samples with it (horus/wire/dynamic.hpp).
struct AnnouncedType {
  std::uint64_t type_hash{};
  std::string signature;
};
HORUS_REFLECT(AnnouncedType, type_hash, signature)

struct Announcement {
  std::uint64_t host_id{};
  std::string host;
  std::string shm_namespace;
  std::uint64_t version{};  // a hash of the content below but rates and counts
  std::uint64_t sent_unix_ns{};
  std::uint32_t heartbeat_ms{};
  std::vector<AnnouncedProcess> processes;
  std::vector<AnnouncedTopic> topics;
  std::vector<AnnouncedType> types;  // once per type hash
};
HORUS_REFLECT(Announcement, host_id, host, shm_namespace, version, sent_unix_ns, heartbeat_ms, processes, topics, types)

struct Request {
  std::uint64_t from_host{};
  std::uint64_t want_host{};  // 0: every host
};
HORUS_REFLECT(Request, from_host, want_host)

}  // namespace horus::fleet

HORUS_API_END
