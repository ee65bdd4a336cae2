// The fleet agent's heartbeats and fleet view (agent.hpp), on the executor's thread: the
// heartbeat of this host (when its process speaks for the host), the hosts heard, lost and
// forgotten, and the fleet view the speaker publishes on horus.fleet.view.<transport>.
#include <algorithm>
#include <vector>

#include "agent.hpp"

namespace horus::fleet::detail {

void Agent::on_heartbeat(const Heartbeat& h) {
  if (h.host_id == 0 || h.host_id == self_) return;
  if (h.host.empty() || h.host.size() > 255 || h.period_ms < kMinHeartbeatMs || h.period_ms > kMaxHeartbeatMs)
    return;  // horus::Fleet counts it as malformed
  const std::uint64_t now = detail::steady_ns();
  // The fleet view: every agent keeps it (it may come to speak for the host), the speaker
  // publishes it. At most kViewHosts (and fleet.max_hosts) hosts: a new one takes the place
  // of the host lost longest ago, or is not tracked (nor echoed) while all of them live.
  auto found = tracked_.find(h.host_id);
  if (found == tracked_.end()) {
    std::vector<std::uint64_t> forgotten;
    const std::size_t max = std::min<std::size_t>(detail::kViewHosts, settings_.max_hosts);
    const bool room = detail::make_room(tracked_, max, lost_since, &forgotten);
    for (const auto id : forgotten) heard_.erase(id);
    if (!room) return;
    found = tracked_.emplace(h.host_id, Tracked{}).first;
    found->second.view.host_id = h.host_id;
    found->second.view.first_seen_unix_ns = detail::unix_ns();
    view_dirty_ = true;
  }
  heard_[h.host_id] = {h.sent_ns, now};
  Tracked& t = found->second;
  const std::int64_t now_unix = host_clock_unix_ns();
  t.link.on_heartbeat(h, self_, now, now_unix);
  ViewedHost& v = t.view;
  if (v.host != h.host || v.period_ms != h.period_ms) view_dirty_ = true;
  v.host = h.host;
  v.period_ms = h.period_ms;
  ++v.heartbeats;
  v.last_seen_unix_ns = now_unix;
  t.last_ns = now;
  if (v.state == static_cast<std::uint32_t>(HostState::Lost)) {
    v.state = static_cast<std::uint32_t>(HostState::Rejoined);
    ++v.rejoins;
    v.lost_since_unix_ns = 0;
    view_dirty_ = true;
  }
  v.rtt_ns = t.link.rtt_ns();
  v.loss = t.link.loss();
  v.clock_offset_ns = t.link.offset_ns();
  v.clock_uncertainty_ns = t.link.uncertainty_ns();
}

void Agent::keep_view(bool speaker) {
  const std::uint64_t now = detail::steady_ns();
  for (auto& [id, t] : tracked_) {
    ViewedHost& v = t.view;
    const std::uint64_t period = std::uint64_t{v.period_ms} * 1'000'000ULL;
    if (v.state != static_cast<std::uint32_t>(HostState::Lost) && now - t.last_ns > period * (settings_.misses + 1)) {
      v.state = static_cast<std::uint32_t>(HostState::Lost);
      v.lost_since_unix_ns = detail::unix_ns();
      view_dirty_ = true;
    }
  }
  std::vector<std::uint64_t> forgotten;
  detail::forget_lost(tracked_, settings_.forget_after, detail::unix_ns(), lost_since, &forgotten);
  for (const auto id : forgotten) heard_.erase(id);
  if (!forgotten.empty()) view_dirty_ = true;
  if (!speaker || !view_) return;
  if (!view_dirty_ && now - view_sent_ns_ < 1'000'000'000ULL) return;
  FleetView view;
  view.host_id = self_;
  view.version = ++view_version_;
  view.made_unix_ns = detail::unix_ns();
  view.hosts.reserve(tracked_.size());
  for (const auto& [id, t] : tracked_) view.hosts.push_back(t.view);
  view_->send(view);
  view_dirty_ = false;
  view_sent_ns_ = now;
}

void Agent::on_request(const Request& r) {
  if (r.want_host != 0 && r.want_host != self_) return;
  {
    std::lock_guard lock(mutex_);
    announce_due_ = std::min(announce_due_, std::chrono::steady_clock::now());
    asked_ = true;
  }
  wake_announcer();
}

void Agent::tick() {
  if (!heartbeat_ || !heartbeat_->is_bridge()) {
    holder_.store(false, std::memory_order_relaxed);
    keep_view(false);
    return;
  }
  if (!holder_.load(std::memory_order_relaxed)) {
    // This process now speaks for the host: announce, and ask every host to, so that this
    // host's processes learn the fleet at once.
    {
      std::lock_guard lock(mutex_);
      announce_due_ = std::chrono::steady_clock::now();
      asked_ = true;
      rescan_ = true;
    }
    holder_.store(true, std::memory_order_relaxed);
    wake_announcer();
    request_->send(Request{self_, 0});
  }
  Heartbeat hb;
  hb.host_id = self_;
  hb.host = name_;
  hb.seq = ++seq_;
  hb.sent_ns = detail::steady_ns();
  hb.sent_unix_ns = host_clock_unix_ns();
  hb.period_ms = static_cast<std::uint32_t>(settings_.heartbeat.count());
  hb.announce_version = sent_version_.load(std::memory_order_relaxed);
  hb.processes = processes_.load(std::memory_order_relaxed);
  hb.topics = topics_.load(std::memory_order_relaxed);
  const std::uint64_t keep_ns = 2'000'000'000ULL + 10 * hb.period_ms * 1'000'000ULL;
  for (auto it = heard_.begin(); it != heard_.end();) {
    const std::uint64_t held = hb.sent_ns - it->second.received_ns;
    if (held > keep_ns) {
      it = heard_.erase(it);
      continue;
    }
    if (hb.echoes.size() < 256) hb.echoes.push_back(HeartbeatEcho{it->first, it->second.sent_ns, held});
    ++it;
  }
  heartbeat_->send(hb);
  keep_view(true);
}

}  // namespace horus::fleet::detail
