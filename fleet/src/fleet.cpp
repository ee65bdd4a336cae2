// horus::Fleet (horus/fleet.hpp): reads the fleet layer's heartbeats and announcements and keeps
// the table of hosts, with their liveliness, on an Executor (the caller's or its own thread).
#include "horus/fleet.hpp"

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <thread>

#include "fleet_internal.hpp"
#include "host_table.hpp"
#include "horus/config.hpp"
#include "horus/discovery/registry.hpp"
#include "horus/executor.hpp"
#include "horus/log.hpp"
#include "horus/shm/shm_segment.hpp"
#include "horus/topic.hpp"
#include "horus/transport_registry.hpp"

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

// What a Fleet holds: its table of hosts (host_table.hpp) behind a mutex, the topics it reads and
// asks on, its callbacks and its executor.
struct Fleet::State {
  std::string transport;
  std::optional<std::string> shm_ns;  // the host's shared-memory namespace (the open's settings)
  std::uint64_t self = fleet::host_id();
  fleet::detail::Presence presence;  // keeps this host announced while the Fleet lives
  Clock::time_point last_check{};    // check()'s previous run (the executor's thread)

  mutable std::mutex mutex;
  std::optional<fleet::detail::HostTable> table;  // made by open() with the settings
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

  // What a message did: counted when refused, its host's announcement asked for when stale.
  void taken(fleet::detail::HostTable::Taken t, std::uint64_t host, std::vector<FleetEvent>& events) {
    using Taken = fleet::detail::HostTable::Taken;
    if (t == Taken::Malformed) malformed.fetch_add(1, std::memory_order_relaxed);
    if (t == Taken::Ask) ask(host);
    emit(events);
  }

  void on_heartbeat(const Heartbeat& h) {
    const auto now = Clock::now();
    const std::uint64_t now_ns = fleet::detail::steady_ns();
    std::vector<FleetEvent> events;
    fleet::detail::HostTable::Taken t;
    {
      std::lock_guard lock(mutex);
      t = table->heartbeat(h, now, now_ns, events);
    }
    taken(t, h.host_id, events);
  }

  void on_announce(const Announcement& a) {
    const auto signatures = fleet::detail::announced_signatures(a);  // outside the lock: hashing
    if (!signatures) {
      malformed.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    const auto now = Clock::now();
    std::vector<FleetEvent> events;
    fleet::detail::HostTable::Taken t;
    {
      std::lock_guard lock(mutex);
      t = table->announce(a, *signatures, now, events);
    }
    taken(t, a.host_id, events);
  }

  // Loss (HostTable::check). An observer whose own executor was held up (this 20 ms check ran a
  // heartbeat period late: the executor was busy or its thread was not scheduled) may have
  // heartbeats waiting, unread, in the topic: it judges nothing until the executor has had a
  // turn to read them, so a busy observer does not report live hosts lost.
  void check() {
    const auto now = Clock::now();
    const auto since = now - last_check;
    last_check = now;
    std::vector<FleetEvent> events;
    {
      std::lock_guard lock(mutex);
      // The check runs every 20 ms: late by more than twice that and a heartbeat period, it stalled.
      if (since > std::max<Clock::duration>(std::chrono::milliseconds(40), table->shortest_period())) return;
      table->check(now, events);
    }
    emit(events);
  }

  // Starts from the fleet view this host's agent keeps (fleet_messages.hpp), as it was when it
  // last published (at most a second ago).
  void seed() {
    auto view = Topic<fleet::FleetView>::open(fleet::detail::view_topic(transport), fleet::detail::view_options());
    if (!view) return;
    auto latest = view->read_latest();
    if (!latest || latest->host_id != self) return;
    std::lock_guard lock(mutex);
    table->seed(*latest, Clock::now(), fleet::detail::unix_ns());
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
  auto taken = Settings::current();  // once, passed down
  if (!taken) return std::unexpected(taken.error());
  auto settings = fleet_settings(*taken);
  if (!settings) return std::unexpected(settings.error());
  auto state = std::make_shared<State>();
  state->transport = options.transport.value_or(settings->transport);
  const std::uint32_t misses = options.misses.value_or(settings->misses);
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
  if (misses == 0) return fail(Errc::InvalidArgument, "horus::Fleet: misses must be at least 1");
  state->table.emplace(fleet::detail::HostTable::Limits{state->self, misses, settings->max_hosts, settings->forget_after});
  if (auto ns = shm::shm_namespace(taken->env().shm_namespace)) state->shm_ns = std::move(*ns);
  auto may = fleet::detail::may_bridge(taken->env().bridge);
  if (!may) return std::unexpected(may.error());
  if (*may) state->presence = fleet::detail::acquire_presence(state->transport, *taken);

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
  std::lock_guard lock(state_->mutex);
  return state_->table->hosts(Clock::now());
}

std::optional<FleetHost> Fleet::host(std::string_view name) const {
  std::lock_guard lock(state_->mutex);
  return state_->table->host(name, Clock::now());
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
  if (const auto& ns = state_->shm_ns) {
    for (const char* t : {fleet::kHeartbeatTopic, fleet::kAnnounceTopic})
      if (auto e = discovery::find_topic(*ns, t)) n += e->malformed;
  }
  return n;
}

}  // namespace horus
