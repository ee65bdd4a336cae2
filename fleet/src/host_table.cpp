// HostTable (host_table.hpp): horus::Fleet's table of hosts.
#include "host_table.hpp"

#include <algorithm>

#include "horus/config.hpp"
#include "horus/wire/dynamic.hpp"

namespace horus::fleet::detail {

std::optional<std::map<std::uint64_t, const std::string*>> announced_signatures(const Announcement& a) {
  if (a.host_id == 0 || a.host.empty() || a.host.size() > 255 || a.processes.size() > kMaxAnnouncedProcesses ||
      a.topics.size() > kMaxAnnouncedTopics || a.types.size() > kMaxAnnouncedTopics)
    return std::nullopt;
  std::map<std::uint64_t, const std::string*> signatures;
  for (const auto& t : a.types) {
    if (wire::signature_hash(t.signature) != t.type_hash) return std::nullopt;  // corrupt, or forged
    signatures[t.type_hash] = &t.signature;
  }
  return signatures;
}

HostTable::Record* HostTable::seen(std::uint64_t id, const std::string& name, Clock::time_point now,
                                   std::vector<FleetEvent>& events) {
  if (!hosts_.contains(id) && !make_room(hosts_, limits_.max_hosts, lost_since_ns)) return nullptr;
  auto [it, fresh] = hosts_.try_emplace(id);
  Record& r = it->second;
  r.host.id = id;
  r.host.name = name;
  r.host.self = id == limits_.self;
  r.last_seen = now;
  if (fresh) {
    r.host.state = HostState::Alive;
    events.push_back({FleetEvent::Kind::Joined, r.host});
  } else if (r.host.state == HostState::Lost) {
    r.host.state = HostState::Rejoined;
    ++r.host.rejoins;
    events.push_back({FleetEvent::Kind::Rejoined, r.host});
  }
  return &r;
}

HostTable::Taken HostTable::heartbeat(const Heartbeat& h, Clock::time_point now, std::uint64_t now_steady_ns,
                                      std::vector<FleetEvent>& events) {
  if (h.host_id == 0 || h.host.empty() || h.host.size() > 255 || h.period_ms < kMinHeartbeatMs ||
      h.period_ms > kMaxHeartbeatMs)
    return Taken::Malformed;
  Record* found = seen(h.host_id, h.host, now, events);
  if (found == nullptr) return Taken::Malformed;
  Record& r = *found;
  r.host.period = std::chrono::milliseconds(h.period_ms);
  ++r.host.heartbeats;
  const std::int64_t now_unix = host_clock_unix_ns();
  r.host.last_seen_unix_ms = now_unix / 1'000'000;
  r.host.lost_since_unix_ms = 0;
  if (h.host_id != limits_.self) {
    r.link.on_heartbeat(h, limits_.self, now_steady_ns, now_unix);
    if (r.link.rtt_ns() >= 0) r.host.rtt = std::chrono::microseconds(r.link.rtt_ns() / 1000);
    // A figure from the view (the agent's longer window) stays until ours spans 5 s.
    if (const double loss = r.link.loss(); loss >= 0 && (r.host.loss < 0 || r.link.span() >= std::chrono::seconds(5)))
      r.host.loss = loss;
    if (r.link.uncertainty_ns() >= 0) {
      r.host.clock_offset = std::chrono::microseconds(r.link.offset_ns() / 1000);
      r.host.clock_uncertainty = std::chrono::microseconds(r.link.uncertainty_ns() / 1000);
    }
  }
  r.version_wanted = h.announce_version;
  // Its announcement is missing or old (lost on the way, or we came late): ask, once a second.
  if (h.announce_version != 0 && h.announce_version != r.version_have && now - r.last_request > std::chrono::seconds(1)) {
    r.last_request = now;
    return Taken::Ask;
  }
  return Taken::Kept;
}

HostTable::Taken HostTable::announce(const Announcement& a, const std::map<std::uint64_t, const std::string*>& signatures,
                                     Clock::time_point now, std::vector<FleetEvent>& events) {
  Record* found = seen(a.host_id, a.host, now, events);
  if (found == nullptr) return Taken::Malformed;
  Record& r = *found;
  if (a.heartbeat_ms >= kMinHeartbeatMs && a.heartbeat_ms <= kMaxHeartbeatMs && r.host.period.count() == 0)
    r.host.period = std::chrono::milliseconds(a.heartbeat_ms);
  r.host.shm_namespace = a.shm_namespace;
  r.host.processes.clear();
  for (const auto& p : a.processes) r.host.processes.push_back({p.pid, p.name, p.start_unix_ns});
  r.host.topics.clear();
  for (const auto& t : a.topics) {
    FleetTopic ft{t.name,     t.type_name, t.type_hash, t.scope,   t.transport, t.publishers,
                  t.subscribers, t.rate_hz, t.messages,  t.dropped, t.message_size, {}};
    if (auto it = signatures.find(t.type_hash); it != signatures.end()) ft.signature = *it->second;
    r.host.topics.push_back(std::move(ft));
  }
  const bool changed = !r.host.announced || r.version_have != a.version;
  r.host.announced = true;
  r.version_have = a.version;
  if (changed) events.push_back({FleetEvent::Kind::Changed, r.host});
  return Taken::Kept;
}

std::chrono::milliseconds HostTable::shortest_period() const {
  auto shortest = std::chrono::milliseconds(100);
  for (const auto& [id, r] : hosts_)
    if (r.host.period.count() > 0) shortest = std::min(shortest, r.host.period);
  return shortest;
}

void HostTable::check(Clock::time_point now, std::vector<FleetEvent>& events) {
  for (auto& [id, r] : hosts_) {
    const auto period = r.host.period.count() > 0 ? r.host.period : std::chrono::milliseconds(100);
    if (r.host.state != HostState::Lost && now - r.last_seen > period * (limits_.misses + 1)) {
      r.host.state = HostState::Lost;
      r.host.lost_since_unix_ms = unix_ns() / 1'000'000;
      r.host.heartbeat_age = std::chrono::duration_cast<std::chrono::milliseconds>(now - r.last_seen);
      events.push_back({FleetEvent::Kind::Lost, r.host});
    }
  }
  forget_lost(hosts_, limits_.forget_after, unix_ns(), lost_since_ns);
}

void HostTable::seed(const FleetView& view, Clock::time_point now, std::int64_t now_unix_ns) {
  for (const auto& v : view.hosts) {
    if (v.host_id == 0 || v.host_id == limits_.self || v.host.empty() || v.state > 2 || hosts_.contains(v.host_id))
      continue;
    if (hosts_.size() >= limits_.max_hosts) break;
    Record& r = hosts_[v.host_id];
    r.host.id = v.host_id;
    r.host.name = v.host;
    r.host.state = static_cast<HostState>(v.state);
    r.host.period = std::chrono::milliseconds(v.period_ms);
    r.host.heartbeats = v.heartbeats;
    r.host.rejoins = v.rejoins;
    r.host.last_seen_unix_ms = v.last_seen_unix_ns / 1'000'000;
    r.host.lost_since_unix_ms = v.lost_since_unix_ns / 1'000'000;
    if (v.rtt_ns >= 0) r.host.rtt = std::chrono::microseconds(v.rtt_ns / 1000);
    r.host.loss = v.loss;
    if (v.clock_uncertainty_ns >= 0) {
      r.host.clock_offset = std::chrono::microseconds(v.clock_offset_ns / 1000);
      r.host.clock_uncertainty = std::chrono::microseconds(v.clock_uncertainty_ns / 1000);
    }
    const auto age = std::chrono::nanoseconds(std::max<std::int64_t>(0, now_unix_ns - v.last_seen_unix_ns));
    r.last_seen = now - std::chrono::duration_cast<Clock::duration>(age);
  }
}

FleetHost HostTable::snapshot(const Record& r, Clock::time_point now) {
  FleetHost h = r.host;
  h.heartbeat_age = std::chrono::duration_cast<std::chrono::milliseconds>(now - r.last_seen);
  return h;
}

std::vector<FleetHost> HostTable::hosts(Clock::time_point now) const {
  std::vector<FleetHost> out;
  for (const auto& [id, r] : hosts_) out.push_back(snapshot(r, now));
  std::sort(out.begin(), out.end(),
            [](const auto& a, const auto& b) { return a.name < b.name || (a.name == b.name && a.id < b.id); });
  return out;
}

std::optional<FleetHost> HostTable::host(std::string_view name, Clock::time_point now) const {
  for (const auto& [id, r] : hosts_)
    if (r.host.name == name) return snapshot(r, now);
  return std::nullopt;
}

}  // namespace horus::fleet::detail
