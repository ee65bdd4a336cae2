// horus::Fleet (horus/fleet.hpp): reads the fleet layer's heartbeats and announcements and keeps
// the table of hosts, with their liveliness, on an Executor (the caller's or its own thread).
#include "horus/fleet.hpp"

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <numeric>
#include <thread>

#include "fleet_internal.hpp"
#include "horus/config.hpp"
#include "horus/discovery/registry.hpp"
#include "horus/executor.hpp"
#include "horus/log.hpp"
#include "horus/shm/shm_segment.hpp"
#include "horus/topic.hpp"
#include "horus/transport_registry.hpp"
#include "horus/wire/dynamic.hpp"

namespace horus {

std::string_view to_string(HostState s) noexcept {
  switch (s) {
    case HostState::Alive: return "alive";
    case HostState::Lost: return "lost";
    case HostState::Rejoined: return "rejoined";
  }
  return "?";
}

std::string_view to_string(FleetEvent::Kind k) noexcept {
  switch (k) {
    case FleetEvent::Kind::Joined: return "joined";
    case FleetEvent::Kind::Lost: return "lost";
    case FleetEvent::Kind::Rejoined: return "rejoined";
    case FleetEvent::Kind::Changed: return "changed";
  }
  return "?";
}

namespace {
using Clock = std::chrono::steady_clock;
using fleet::Announcement;
using fleet::Heartbeat;
using fleet::Request;
}  // namespace

// What Fleet::State knows of a host. (Not in the anonymous namespace: a member of Fleet::State,
// which has linkage, may not have a type without it. The library exports none of this.)
namespace fleet_view {
struct Record {
  FleetHost host;
  fleet::detail::LinkStats link;
  std::chrono::steady_clock::time_point last_seen{};
  std::uint64_t version_have = 0;     // of the announcement we hold
  std::uint64_t version_wanted = 0;   // the latest heartbeat's
  std::chrono::steady_clock::time_point last_request{};
};
}  // namespace fleet_view
using fleet_view::Record;

struct Fleet::State {
  std::string transport;
  std::uint64_t self = fleet::host_id();
  std::uint32_t misses = 3;
  std::size_t max_hosts = 1024;
  std::chrono::nanoseconds forget_after = std::chrono::hours(1);
  fleet::detail::Presence presence;  // keeps this host announced while the Fleet lives
  Clock::time_point last_check{};    // check()'s previous run (the executor's thread)

  mutable std::mutex mutex;
  std::map<std::uint64_t, Record> hosts;
  std::map<CallbackId, std::function<void(const FleetEvent&)>> callbacks;
  CallbackId next_callback = 1;
  std::atomic<std::uint64_t> malformed{0};

  std::mutex send_mutex;
  std::optional<Topic<Request>> request;

  Executor* executor = nullptr;
  std::unique_ptr<Executor> own;  // open() without an executor
  std::thread thread;
  std::vector<Executor::Id> ids;

  void ask(std::uint64_t want) {
    std::lock_guard lock(send_mutex);
    if (request) request->send(Request{self, want});
  }

  void emit(std::vector<FleetEvent>& events) {
    if (events.empty()) return;
    std::vector<std::function<void(const FleetEvent&)>> cbs;
    {
      std::lock_guard lock(mutex);
      for (const auto& [id, cb] : callbacks) cbs.push_back(cb);
    }
    for (const auto& e : events)
      for (const auto& cb : cbs) cb(e);
    events.clear();
  }

  static std::int64_t lost_since_ns(const Record& r) { return r.host.lost_since_unix_ms * 1'000'000; }

  // A sign of life from `id`: a new host joins (when there is room: nullptr and counted as
  // malformed when max_hosts hosts live), a lost one rejoins.
  Record* seen(std::uint64_t id, const std::string& name, Clock::time_point now, std::vector<FleetEvent>& events) {
    if (!hosts.contains(id) && !fleet::detail::make_room(hosts, max_hosts, lost_since_ns)) {
      malformed.fetch_add(1, std::memory_order_relaxed);
      return nullptr;
    }
    auto [it, fresh] = hosts.try_emplace(id);
    Record& r = it->second;
    r.host.id = id;
    r.host.name = name;
    r.host.self = id == self;
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

  void on_heartbeat(const Heartbeat& h) {
    if (h.host_id == 0 || h.host.empty() || h.host.size() > 255 || h.period_ms < kMinHeartbeatMs ||
        h.period_ms > kMaxHeartbeatMs) {
      malformed.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    const auto now = Clock::now();
    const std::uint64_t now_ns = fleet::detail::steady_ns();
    std::vector<FleetEvent> events;
    bool want = false;
    {
      std::lock_guard lock(mutex);
      Record* found = seen(h.host_id, h.host, now, events);
      if (found == nullptr) return;
      Record& r = *found;
      r.host.period = std::chrono::milliseconds(h.period_ms);
      ++r.host.heartbeats;
      const std::int64_t now_unix = fleet::host_clock_unix_ns();
      r.host.last_seen_unix_ms = now_unix / 1'000'000;
      r.host.lost_since_unix_ms = 0;
      if (h.host_id != self) {
        r.link.on_heartbeat(h, self, now_ns, now_unix);
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
        want = true;
      }
    }
    if (want) ask(h.host_id);
    emit(events);
  }

  void on_announce(const Announcement& a) {
    if (a.host_id == 0 || a.host.empty() || a.host.size() > 255 || a.processes.size() > fleet::detail::kMaxAnnouncedProcesses ||
        a.topics.size() > fleet::detail::kMaxAnnouncedTopics || a.types.size() > fleet::detail::kMaxAnnouncedTopics) {
      malformed.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    std::map<std::uint64_t, const std::string*> signatures;
    for (const auto& t : a.types) {
      if (wire::signature_hash(t.signature) != t.type_hash) {  // corrupt, or forged
        malformed.fetch_add(1, std::memory_order_relaxed);
        return;
      }
      signatures[t.type_hash] = &t.signature;
    }
    const auto now = Clock::now();
    std::vector<FleetEvent> events;
    {
      std::lock_guard lock(mutex);
      Record* found = seen(a.host_id, a.host, now, events);
      if (found == nullptr) return;
      Record& r = *found;
      if (a.heartbeat_ms >= kMinHeartbeatMs && a.heartbeat_ms <= kMaxHeartbeatMs && r.host.period.count() == 0)
        r.host.period = std::chrono::milliseconds(a.heartbeat_ms);
      r.host.shm_namespace = a.shm_namespace;
      r.host.processes.clear();
      for (const auto& p : a.processes) r.host.processes.push_back({p.pid, p.name, p.start_unix_ns});
      r.host.topics.clear();
      for (const auto& t : a.topics) {
        FleetTopic ft{t.name, t.type_name, t.type_hash, t.scope, t.transport, t.publishers, t.subscribers,
                      t.rate_hz, t.messages, t.dropped, t.message_size, {}};
        if (auto it = signatures.find(t.type_hash); it != signatures.end()) ft.signature = *it->second;
        r.host.topics.push_back(std::move(ft));
      }
      const bool changed = !r.host.announced || r.version_have != a.version;
      r.host.announced = true;
      r.version_have = a.version;
      if (changed) events.push_back({FleetEvent::Kind::Changed, r.host});
    }
    emit(events);
  }

  // Loss: `misses` heartbeat periods without a sign of life, plus one period of tolerance.
  // An observer whose own executor was held up (this 20 ms check ran a heartbeat period late:
  // the executor was busy or its thread was not scheduled) may have heartbeats waiting, unread,
  // in the topic: it judges nothing until the executor has had a turn to read them, so a busy
  // observer does not report live hosts lost.
  void check() {
    const auto now = Clock::now();
    const auto since = now - last_check;
    last_check = now;
    std::vector<FleetEvent> events;
    {
      std::lock_guard lock(mutex);
      const auto shortest = std::accumulate(hosts.begin(), hosts.end(), std::chrono::milliseconds(100),
                                            [](std::chrono::milliseconds m, const auto& h) {
                                              return h.second.host.period.count() > 0 ? std::min(m, h.second.host.period) : m;
                                            });
      // The check runs every 20 ms: late by more than twice that and a heartbeat period, it stalled.
      if (since > std::max<Clock::duration>(std::chrono::milliseconds(40), shortest)) return;
      for (auto& [id, r] : hosts) {
        const auto period = r.host.period.count() > 0 ? r.host.period : std::chrono::milliseconds(100);
        if (r.host.state != HostState::Lost && now - r.last_seen > period * (misses + 1)) {
          r.host.state = HostState::Lost;
          r.host.lost_since_unix_ms = fleet::detail::unix_ns() / 1'000'000;
          r.host.heartbeat_age = std::chrono::duration_cast<std::chrono::milliseconds>(now - r.last_seen);
          events.push_back({FleetEvent::Kind::Lost, r.host});
        }
      }
      fleet::detail::forget_lost(hosts, forget_after, fleet::detail::unix_ns(), lost_since_ns);
    }
    emit(events);
  }

  // Starts from the fleet view this host's agent keeps (fleet_messages.hpp): the hosts it saw,
  // lost ones included, as they were when it last published (at most a second ago).
  void seed() {
    auto view = Topic<fleet::FleetView>::open(fleet::detail::view_topic(transport), fleet::detail::view_options());
    if (!view) return;
    auto latest = view->read_latest();
    if (!latest || latest->host_id != self) return;
    const auto now = Clock::now();
    const std::int64_t now_unix = fleet::detail::unix_ns();
    std::lock_guard lock(mutex);
    for (const auto& v : latest->hosts) {
      if (v.host_id == 0 || v.host_id == self || v.host.empty() || v.state > 2 || hosts.contains(v.host_id)) continue;
      if (hosts.size() >= max_hosts) break;
      Record& r = hosts[v.host_id];
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
      const auto age = std::chrono::nanoseconds(std::max<std::int64_t>(0, now_unix - v.last_seen_unix_ns));
      r.last_seen = now - std::chrono::duration_cast<Clock::duration>(age);
    }
  }

  FleetHost snapshot(const Record& r, Clock::time_point now) const {
    FleetHost h = r.host;
    h.heartbeat_age = std::chrono::duration_cast<std::chrono::milliseconds>(now - r.last_seen);
    return h;
  }
};

Result<std::unique_ptr<Fleet>> Fleet::open(FleetOptions options) {
  auto own = std::make_unique<Executor>();
  auto f = open(*own, std::move(options));
  if (!f) return f;
  Fleet& fleet = **f;
  fleet.state_->own = std::move(own);
  Executor* ex = fleet.state_->own.get();
  fleet.state_->thread = std::thread([ex] { ex->spin(); });
  return f;
}

Result<std::unique_ptr<Fleet>> Fleet::open(Executor& executor, FleetOptions options) {
  auto settings = fleet_settings();
  if (!settings) return std::unexpected(settings.error());
  auto state = std::make_shared<State>();
  state->transport = options.transport.value_or(settings->transport);
  state->misses = options.misses.value_or(settings->misses);
  state->max_hosts = settings->max_hosts;
  state->forget_after = settings->forget_after;
  if (state->transport.empty())
    return fail(Errc::Config,
                "horus::Fleet: no network backend to watch the fleet on; set HORUS_BACKEND=cyclonedds|fastdds|lcm, "
                "network.backend in the configuration file (HORUS_CONFIG), or FleetOptions::transport");
  const auto* info = net::find_transport(state->transport);
  if (info == nullptr) {
    std::string valid;
    for (const auto& n : net::transport_names()) valid += (valid.empty() ? "" : ", ") + n;
    return fail(Errc::Config, "horus::Fleet: unknown network backend '" + state->transport + "'; this build has " +
                                  (valid.empty() ? std::string("none") : valid));
  }
  state->transport = std::string(info->name);
  if (state->misses == 0) return fail(Errc::InvalidArgument, "horus::Fleet: misses must be at least 1");
  auto may = fleet::detail::may_bridge_from_environment();
  if (!may) return std::unexpected(may.error());
  if (*may) state->presence = fleet::detail::acquire_presence(state->transport);

  auto rq = Topic<Request>::open(fleet::kRequestTopic, fleet::detail::request_options(state->transport));
  if (!rq) return std::unexpected(rq.error());
  state->request.emplace(std::move(*rq));
  state->request->publish_only();
  state->executor = &executor;
  try {
    std::weak_ptr<State> weak = state;
    state->ids.push_back(executor.subscribe<Heartbeat>(
        fleet::kHeartbeatTopic, fleet::detail::heartbeat_options(state->transport), [weak](const Heartbeat& h) {
          if (auto s = weak.lock()) s->on_heartbeat(h);
        }));
    state->ids.push_back(executor.subscribe<Announcement>(
        fleet::kAnnounceTopic, fleet::detail::announce_options(state->transport), [weak](const Announcement& a) {
          if (auto s = weak.lock()) s->on_announce(a);
        }));
    state->ids.push_back(executor.every(std::chrono::milliseconds(20), [weak] {
      if (auto s = weak.lock()) s->check();
    }));
  } catch (const Exception& e) {
    for (auto id : state->ids) executor.remove(id);
    return std::unexpected(e.error());
  }
  state->seed();
  state->ask(0);
  return std::unique_ptr<Fleet>(new Fleet(std::move(state)));
}

Fleet::~Fleet() {
  if (!state_) return;
  for (auto id : state_->ids) state_->executor->remove(id);
  if (state_->own) {
    state_->own->stop();
    if (state_->thread.joinable()) state_->thread.join();
  }
}

std::vector<FleetHost> Fleet::hosts() const {
  const auto now = Clock::now();
  std::vector<FleetHost> out;
  std::lock_guard lock(state_->mutex);
  for (const auto& [id, r] : state_->hosts) out.push_back(state_->snapshot(r, now));
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.name < b.name || (a.name == b.name && a.id < b.id); });
  return out;
}

std::optional<FleetHost> Fleet::host(std::string_view name) const {
  const auto now = Clock::now();
  std::lock_guard lock(state_->mutex);
  for (const auto& [id, r] : state_->hosts)
    if (r.host.name == name) return state_->snapshot(r, now);
  return std::nullopt;
}

std::uint64_t Fleet::self_id() const noexcept { return state_->self; }
const std::string& Fleet::transport() const noexcept { return state_->transport; }

Fleet::CallbackId Fleet::on_change(std::function<void(const FleetEvent&)> callback) {
  std::lock_guard lock(state_->mutex);
  const CallbackId id = state_->next_callback++;
  state_->callbacks.emplace(id, std::move(callback));
  return id;
}

bool Fleet::remove(CallbackId id) {
  std::lock_guard lock(state_->mutex);
  return state_->callbacks.erase(id) != 0;
}

void Fleet::refresh() { state_->ask(0); }

std::uint64_t Fleet::malformed() const {
  std::uint64_t n = state_->malformed.load(std::memory_order_relaxed);
  // What the host's bridges of the two topics could not decode (counted in their segments).
  if (auto ns = shm::shm_namespace()) {
    for (const char* t : {fleet::kHeartbeatTopic, fleet::kAnnounceTopic})
      if (auto e = discovery::find_topic(*ns, t)) n += e->malformed;
  }
  return n;
}

}  // namespace horus
