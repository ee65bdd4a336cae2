// The bridge of one fleet topic in one process (bridge.hpp): opening and closing, becoming the
// holder, the engine's calls, exporting. Receiving is bridge_import.cpp, the hand-over
// bridge_handover.cpp, the budget bridge_budget.cpp.
#include "bridge.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "horus/detail/bridge_port.hpp"
#include "horus/detail/process.hpp"
#include "horus/log.hpp"
#include "horus/shm/doorbell.hpp"

namespace horus::fleet::detail {

using horus::detail::log;

namespace {
constexpr auto kEchoTtl = std::chrono::seconds(2);            // how long our own sample may take to come back

std::atomic<int> g_network_pid{0};  // the process that created this process's transports


}  // namespace

// A 64-bit hash of a sample's bytes (the echo ledger), four independent lanes of 8 bytes.
std::uint64_t body_hash(std::span<const std::byte> b) noexcept {
  constexpr std::uint64_t kMul = 0x9E37'79B9'7F4A'7C15ULL;
  std::uint64_t h[4] = {b.size(), 0x243F'6A88'85A3'08D3ULL, 0x1319'8A2E'0370'7344ULL, 0xA409'3822'299F'31D0ULL};
  std::size_t i = 0;
  const std::byte* p = b.data();
  for (; i + 32 <= b.size(); i += 32) {
    for (int k = 0; k < 4; ++k) {
      std::uint64_t w;
      std::memcpy(&w, p + i + 8 * k, 8);
      h[k] = (h[k] ^ w) * kMul;
      h[k] ^= h[k] >> 29;
    }
  }
  std::uint64_t tail = 0;
  for (int shift = 0; i < b.size(); ++i, shift = (shift + 8) & 63) {
    tail ^= static_cast<std::uint64_t>(std::to_integer<std::uint8_t>(p[i])) << shift;
    if (shift == 56) {
      h[0] = (h[0] ^ tail) * kMul;
      tail = 0;
    }
  }
  std::uint64_t r = (h[0] ^ tail) * kMul;
  for (int k = 1; k < 4; ++k) r = (r ^ h[k] ^ (h[k] >> 31)) * kMul;
  return r ^ (r >> 32);
}

// --- the echo ledger ------------------------------------------------------------------------

void EchoLedger::add(std::uint64_t h) {
  std::lock_guard lock(mutex_);
  expire(Clock::now());
  order_.emplace_back(Clock::now(), h);
  ++count_[h];
}

bool EchoLedger::consume(std::uint64_t h) {
  std::lock_guard lock(mutex_);
  expire(Clock::now());
  auto it = count_.find(h);
  if (it == count_.end()) return false;
  if (--it->second == 0) count_.erase(it);
  return true;
}

void EchoLedger::expire(Clock::time_point now) {
  while (!order_.empty() && now - order_.front().first > kEchoTtl) {
    if (auto it = count_.find(order_.front().second); it != count_.end() && --it->second == 0) count_.erase(it);
    order_.pop_front();
  }
}

// HORUS_BRIDGE: "0" keeps this process from ever bridging a fleet topic (it still uses them
// through shared memory; another process of the host bridges); "1" or unset: it may.
Result<bool> may_bridge(std::string_view v) {
  if (v.empty() || v == "1") return true;
  if (v == "0") return false;
  return fail(Errc::Config, fmt::format("HORUS_BRIDGE='{}' is not valid; expected 0 (this process never bridges "
                                        "fleet topics to the network) or 1 (it may; the default)",
                                        v));
}

// --- a process that never bridges (HORUS_BRIDGE=0) --------------------------------------------

namespace {
// Shared memory only: what the host's bridge (another process) publishes in the segment.
class PassiveLink final : public horus::detail::NetworkLink {
 public:
  PassiveLink(horus::detail::TopicCore& core, const net::Qos& qos) : core_(core), qos_(qos) {}
  Result<void> join(const TopicOptions& options) override { return check_qos(core_.name, qos_, options); }
  std::uint64_t dropped() const noexcept override { return bridge().dropped.load(std::memory_order_relaxed); }
  std::uint32_t remote_publishers() const noexcept override {
    return bridge().matched_publishers.load(std::memory_order_relaxed);
  }
  std::uint32_t remote_subscribers() const noexcept override {
    return bridge().matched_subscribers.load(std::memory_order_relaxed);
  }
  std::uint64_t errors() const noexcept override { return 0; }

 private:
  shm::BridgeState& bridge() const noexcept { return core_.segment->bridge(); }
  horus::detail::TopicCore& core_;
  net::Qos qos_;
};
}  // namespace

Result<void> check_qos(const std::string& topic, const net::Qos& have, const TopicOptions& options) {
  // The topic's bridge exists: a handle asking for another QoS is an error, not ignored.
  if ((options.reliability && *options.reliability != have.reliability) ||
      (options.durability && *options.durability != have.durability))
    return fail(Errc::ConfigMismatch,
                "topic '" + topic + "' is open in this process as " + std::string(net::to_string(have.reliability)) +
                    ", " + std::string(net::to_string(have.durability)) +
                    "; cannot open it with another reliability or durability (open it with the same, or "
                    "without either to accept them)");
  return {};
}

// --- opening and closing ----------------------------------------------------------------------

Bridge::Bridge(horus::detail::TopicCore& core, const horus::detail::WireOps& ops, const net::Qos& qos,
               std::shared_ptr<Engine> engine, std::shared_ptr<net::Transport> transport)
    : core_(core),
      ops_(ops),
      qos_(qos),
      engine_(std::move(engine)),
      transport_(std::move(transport)),
      info_(engine_->info()),
      format_(info_.format),
      creator_pid_(horus::detail::current_pid()) {
  loopback_ = transport_->delivers_own_samples();
  hold_ = qos_.reliability == net::Reliability::Reliable && transport_->holds_samples();
}

Result<std::unique_ptr<horus::detail::NetworkLink>> Bridge::open(horus::detail::TopicCore& core,
                                                                 const horus::detail::WireOps& ops,
                                                                 const net::Qos& qos, const TopicOptions& options,
                                                                 const Settings& settings) {
  const auto* info = core.transport;  // found once, when the topic opened
  if (info == nullptr)
    return fail(Errc::Config,
                fmt::format("topic '{}': this build of horus has no {} backend", core.name, to_string(core.backend)));
  if (!ops.expressible(info->format))
    return fail(Errc::Config, "topic '" + core.name + "': " + core.type_name +
                                  " cannot travel over LCM: it has a variable-size array of variable-size arrays "
                                  "or an array of size 0, which LCM types cannot express (horus/wire/"
                                  "lcm_mapping.hpp); use another backend for it");
  if (const int owner = g_network_pid.load(); owner != 0 && owner != horus::detail::current_pid())
    return fail(Errc::Io, fmt::format("topic '{}': this process was forked from pid {} after that process used {}; "
                                      "network transports (DDS participants, LCM instances) do not survive fork() "
                                      "(their threads stay in the parent). Open network topics before forking only "
                                      "in the process that keeps them, or exec the child",
                                      core.name, owner, to_string(core.backend)));
  auto may = may_bridge(settings.env().bridge);
  if (!may) return std::unexpected(std::move(may.error()));
  if (!*may) return std::unique_ptr<horus::detail::NetworkLink>(new PassiveLink(core, qos));  // HORUS_BRIDGE=0
  std::optional<Ros2Wire> ros2;
  net::Qos wire_qos = qos;
  if (options.ros2 && options.ros2->enabled) {  // on the ROS 2 graph: rt/<name>, its type, its QoS
    auto w = resolve_ros2(core, *options.ros2, info->name);
    if (!w) return std::unexpected(std::move(w.error()));
    apply_ros2_qos(wire_qos, w->qos, options);
    ros2 = std::move(*w);
  }
  auto wire = ros2 ? Result<std::string>(ros2->wire_topic()) : info->wire_name(core.name);
  if (!wire) return std::unexpected(std::move(wire.error()));
  auto engine = Engine::of(*info, settings);  // its network settings: HORUS_DOMAIN_ID, HORUS_LCM_URL, the file
  if (!engine) return std::unexpected(std::move(engine.error()));
  g_network_pid.store(horus::detail::current_pid());
  auto transport = (*engine)->transport_for(core.name);
  if (!transport) return std::unexpected(std::move(transport.error()));
  std::unique_ptr<Bridge> b(new Bridge(core, ops, wire_qos, std::move(*engine), std::move(*transport)));
  b->wire_topic_ = std::move(*wire);
  if (ros2) {
    auto node = ros2_node_of(settings);
    if (!node) return std::unexpected(std::move(node.error()));
    auto graph = Ros2Graph::of(b->transport_, *node);
    if (!graph) return std::unexpected(std::move(graph.error()));
    b->ros2_graph_ = std::move(*graph);
    b->map_ros2(std::move(*ros2));
  }
  b->set_budget(options, settings.file);
  const auto claim = b->segment().claim_bridge();
  if (claim == shm::ShmSegment::BridgeClaim::Claimed || claim == shm::ShmSegment::BridgeClaim::TookOver) {
    if (auto ok = b->become_holder(claim == shm::ShmSegment::BridgeClaim::TookOver); !ok) {
      b->segment().release_bridge();
      return std::unexpected(std::move(ok.error()));  // ~Bridge: never added, remove() finds nothing
    }
  }
  b->engine_->add(*b);
  if (b->is_holder()) b->attach();
  // The fleet layer's own topics (horus.fleet.*) do not keep the host announced; the others do.
  if (!core.name.starts_with(kFleetTopicPrefix)) b->presence_ = acquire_presence(std::string(info->name), settings);
  return std::unique_ptr<horus::detail::NetworkLink>(std::move(b));
}

Bridge::~Bridge() {
  if (horus::detail::current_pid() != creator_pid_) {
    // A forked child's copy: the engine's threads and the participant's live in the parent
    // only. Deleting the endpoint here would hang or tell peers the parent's are gone.
    (void)endpoint_.release();
    (void)port_.release();
    new std::shared_ptr<Engine>(std::move(engine_));  // never released in the child
    new std::shared_ptr<net::Transport>(std::move(transport_));
    new std::shared_ptr<Ros2Graph>(std::move(ros2_graph_));
    new Presence(std::move(presence_));
    return;
  }
  stop_.store(true, std::memory_order_release);
  core_.inline_export.active.store(false, std::memory_order_release);
  engine_->remove(*this);
  leave();
  presence_.reset();
}

void Bridge::leave() noexcept {
  core_.inline_export.active.store(false, std::memory_order_release);  // (a takeover may have set it)
  // Wait for an exporter in progress (a reliable write gives up within its blocking bound).
  while (export_busy_.exchange(true, std::memory_order_acquire)) std::this_thread::yield();
  if (holder_.load(std::memory_order_relaxed) && !gated_.load(std::memory_order_relaxed)) drain();
  if (has_latest_) {  // the budget held it back and the topic closes: it will not go out
    has_latest_ = false;
    budget_drop();
  }
  if (attached_.exchange(false))
    shm::engine_leave(core_.ring.doorbell(), core_.ring.subscriber(port_->entry()).waiting, forward_);
  close_endpoint();
  if (const std::uint64_t mine = segment().bridge_word(); mine != 0) {  // it had asked for the bridge
    std::uint64_t w = mine;
    state().handover.compare_exchange_strong(w, 0, std::memory_order_acq_rel);
  }
  if (handing_to_ != 0) finish_hand_over();  // closing while it hands the bridge over: hand it now
  // Handed over: the entry and the lane are the new holder's (or recorded for it): let go of
  // them without freeing them.
  if (port_stale_ && port_) port_->leave();
  for (auto& p : retired_ports_) p->leave();
  if (holder_.load(std::memory_order_relaxed)) {
    state().matched_publishers.store(0, std::memory_order_relaxed);
    state().matched_subscribers.store(0, std::memory_order_relaxed);
    port_->leave();  // recorded in the segment: the next holder adopts them
    segment().release_bridge();
  }
  port_.reset();
}

Result<void> Bridge::join(const TopicOptions& options) {
  if (auto ok = check_qos(core_.name, qos_, options); !ok) return ok;
  update_receiving();  // this handle subscribed: a paused bridge of this process resumes now
  return {};
}

// --- becoming the holder -------------------------------------------------------------------

Result<void> Bridge::become_holder(bool takeover) {
  becoming_.store(true, std::memory_order_release);
  struct Done {
    std::atomic<bool>& flag;
    ~Done() { flag.store(false, std::memory_order_release); }
  } done{becoming_};
  if (port_stale_) {  // handed over before: the old port's entry and lane are someone else's now
    retired_ports_.push_back(std::move(port_));
    port_stale_ = false;
  }
  if (!port_) port_ = ops_.make_port(core_);
  const std::uint32_t readers_before = state().matched_subscribers.load(std::memory_order_relaxed);
  bool inherited = false;
  segment().inherit_bridge([&](shm::ShmSegment::Inheritance& in) {
    if (in.export_entry && port_->take_entry(*in.export_entry, in.export_token)) {
      in.export_entry.reset();
      inherited = true;
    }
    if (in.import_lane && port_->take_lane(*in.import_lane, in.import_token)) in.import_lane.reset();
    // It had read a message and died before the transport took it: maybe sent, never twice.
    if (in.inflight != 0) state().dropped.fetch_add(1, std::memory_order_relaxed);
  });
  if (!port_->has_entry() && !port_->take_entry(0, 0))
    return fail(Errc::LimitReached, fmt::format("topic '{}': its bridge found no free subscriber entry (all {} "
                                                "in use); nothing of this host reaches the fleet",
                                                core_.name, shm::kMaxSubscribers));
  if (!port_->has_lane() && !port_->take_lane(0, 0))
    return fail(Errc::LimitReached, fmt::format("topic '{}': its bridge found no free publisher lane (all {} "
                                                "in use); nothing of the fleet reaches this host",
                                                core_.name, shm::kMaxPublishers));
  segment().record_bridge_export(port_->entry(), port_->entry_token());
  segment().record_bridge_import(port_->lane(), port_->lane_token());
  export_lost_seen_ = port_->export_lost();
  // An endpoint opened for a hand-over matched what the predecessor's had: no gate.
  const bool prematched = prematched_ && endpoint_ != nullptr;
  prematched_ = false;
  if (!prematched) {
    if (auto ok = open_endpoint(host_subscribers() != 0); !ok) {
      port_->leave();  // recorded: the next holder adopts them
      return ok;
    }
  } else {
    receiving_.store(true, std::memory_order_relaxed);  // as it was opened; update_receiving() follows
  }
  if (!prematched && (takeover || inherited) && readers_before != 0) {
    // The readers that matched the predecessor's writer must match ours before the backlog
    // goes out, and then see it (discovery_settle), or a volatile reader would miss it
    // (bounded: a reader may have left). The control thread opens the gate (control()).
    gate_readers_ = readers_before;
    gate_opened_ = Clock::now();
    gate_matched_ = {};
    gate_until_ = gate_opened_ + kMatchWait;
    gated_.store(true, std::memory_order_release);
  }
  holder_.store(true, std::memory_order_release);
  endpoint_ready_.store(true, std::memory_order_release);
  publish_matches();
  if (prematched) update_receiving();
  return {};
}

Result<void> Bridge::open_endpoint(bool receive) {
  net::EndpointSpec spec;
  spec.topic = core_.name;
  spec.wire_topic = wire_topic_;
  spec.type_name = ros2_ ? ros2_->dds_type : core_.type_name;
  spec.type_hash = core_.type_hash;
  if (ros2_) spec.user_data = ros2_->user_data();
  spec.qos = qos_;
  spec.max_message_bytes = core_.pool ? core_.pool.slot_bytes() : core_.ring.payload_size();
  receiving_.store(receive, std::memory_order_relaxed);
  spec.receive = receive;
  auto endpoint = transport_->open(spec, *this);
  if (!endpoint) return std::unexpected(std::move(endpoint.error()));
  std::lock_guard lock(endpoint_mutex_);
  endpoint_ = std::move(*endpoint);
  if (ros2_graph_) ros2_graph_->add(this, *endpoint_);  // its writer and reader on the ROS 2 graph
  return {};
}

void Bridge::close_endpoint() noexcept {
  std::lock_guard receiving(receiving_mutex_);  // no opening handle is inside update_receiving()
  std::lock_guard lock(endpoint_mutex_);        // the import pump is not inside take_held()
  endpoint_ready_.store(false, std::memory_order_release);
  if (ros2_graph_ && endpoint_) ros2_graph_->remove(this);
  endpoint_.reset();  // no callback after this
}

void Bridge::attach() noexcept {
  forward_ = engine_->forward(*this);
  shm::engine_join(core_.ring.doorbell(), core_.ring.subscriber(port_->entry()).waiting, forward_);
  attached_.store(true, std::memory_order_release);
  if (!gated_.load(std::memory_order_acquire)) {
    activate_inline();
  }
  engine_->recheck(*this);  // what the host's publishers wrote before: export it now
}

// --- the engine's calls --------------------------------------------------------------------

void Bridge::service() noexcept {
  if (!attached_.load(std::memory_order_acquire)) return;
  shm::arm_bridge(core_.ring.doorbell());  // armed again, then look: a later send wakes us
  if (state().handover.load(std::memory_order_relaxed) != 0) [[unlikely]] {
    // Asked for the bridge: the control thread answers (it may close the endpoint, which waits).
    const std::int64_t now = now_ns();
    if (now - handover_looked_ns_ > std::chrono::duration_cast<Clock::duration>(std::chrono::milliseconds(20)).count()) {
      handover_looked_ns_ = now;
      try {
        engine_->look(*this);
      } catch (...) {
      }
    }
  }
  if (!gated_.load(std::memory_order_acquire) && !export_busy_.exchange(true, std::memory_order_acquire)) {
    drain();
    release_export();
  }
  update_receiving();
  if (matches_changed_.exchange(false, std::memory_order_acq_rel)) publish_matches();
}

Clock::time_point Bridge::control(Clock::time_point now, bool gone) noexcept {
  if (stop_.load(std::memory_order_relaxed)) return Clock::time_point::max();
  if (const auto at = hand_over_due(now)) return *at;
  if (holder_.load(std::memory_order_acquire)) {
    if (gated_.load(std::memory_order_acquire)) {
      std::uint32_t matched = 0;
      try {
        matched = endpoint_->matched_subscribers();
      } catch (...) {
      }
      if (matched < gate_readers_ && now < gate_until_) return now + std::chrono::milliseconds(1);
      if (matched >= gate_readers_) {
        if (gate_matched_ == Clock::time_point{}) gate_matched_ = now;
        const auto open_at =
            gate_matched_ + std::max<Clock::duration>(discovery_settle(gate_matched_ - gate_opened_), kTakeoverSettle);
        if (now < open_at) return open_at;
      }
      gated_.store(false, std::memory_order_release);
      if (attached_.load(std::memory_order_acquire)) activate_inline();
      engine_->notify(*this);
    }
    // The matched counts come with the transport's on_matched, receiving follows the host's
    // subscribers through the doorbell (service()): nothing to do on a timer.
    return Clock::time_point::max();
  }
  // A watcher is due when something happened (engine.cpp): its holder's pidfd fired, a claim was
  // given up on the host, or it was just added; it looks at the claim word and claims when
  // nobody (alive) holds the bridge.
  const std::uint64_t owner = state().owner.load(std::memory_order_acquire);
  const std::uint64_t mine = segment().bridge_word();
  // A watcher that publishes asks for the bridge (the hand-over); the holder hands it over by
  // writing our word into the claim (Ours below).
  auto next = Clock::time_point::max();
  if (owner != mine && (ask_ != Ask::Idle || publishes_.load(std::memory_order_relaxed)))
    next = handover_step(now, owner);
  if (retry_claim_ && now < retry_at_) return std::min(next, retry_at_);
  if (owner != 0 && owner != mine && owner == seen_owner_ && !gone && !retry_claim_) return next;
  seen_owner_ = owner;
  const auto claim = segment().claim_bridge();
  if (claim == shm::ShmSegment::BridgeClaim::Held) return next;
  const bool takeover = claim == shm::ShmSegment::BridgeClaim::TookOver;
  const bool handed = claim == shm::ShmSegment::BridgeClaim::Ours;
  if (auto ok = become_holder(takeover); !ok) {
    log().error("topic '{}': this process could not take over the host's bridge to {}: {}; retrying in 1 s",
                core_.name, info_.name, ok.error().message());
    segment().release_bridge();
    if (ask_ != Ask::Idle) cancel_ask(false);
    retry_claim_ = true;
    retry_at_ = now + std::chrono::seconds(1);
    return retry_at_;
  }
  retry_claim_ = false;
  if (handed || ask_ != Ask::Idle) asked_done();
  log().info("topic '{}': this process (pid {}) now bridges the host to {}{}", core_.name, ::getpid(), info_.name,
             takeover ? " (it took over from a process that is gone)"
             : handed ? " (handed over by a process that does not publish on it: its sends export inline)"
                      : "");
  attach();
  return gated_.load() ? now + std::chrono::milliseconds(1) : Clock::time_point::max();
}

pid_t Bridge::watched_pid() const noexcept {
  if (holder_.load(std::memory_order_acquire)) return 0;
  return static_cast<pid_t>(state().owner.load(std::memory_order_acquire) >> 32);
}

// --- exporting -------------------------------------------------------------------------------

void Bridge::export_inline_trampoline(void* self) noexcept { static_cast<Bridge*>(self)->export_inline(); }

void Bridge::activate_inline() noexcept {
  core_.inline_export.ctx = this;
  core_.inline_export.run = &Bridge::export_inline_trampoline;
  core_.inline_export.generation = shm::fork_generation();
  core_.inline_export.active.store(true, std::memory_order_release);
}

// A publishing thread of this process, right after its send: exports unless another thread
// does (it looks again when it stops, release_export()).
void Bridge::export_inline() noexcept {
  if (backlog_.load(std::memory_order_acquire)) return;  // the engine retries the stash
  if (export_busy_.exchange(true, std::memory_order_acquire)) return;
  if (!holder_.load(std::memory_order_acquire)) {  // handed over meanwhile (hand_over() held export_busy_)
    export_busy_.store(false, std::memory_order_release);
    return;
  }
  drain();
  release_export();
}

bool Bridge::has_export_work() const noexcept {
  return core_.ring.has_unread_except(port_->entry(), port_->entry_token(), port_->lane());
}

// Stops exporting, then looks once more: a message written while we held export_busy_ by a
// thread that found it taken would otherwise wait for the next send.
void Bridge::release_export() noexcept {
  for (;;) {
    export_busy_.store(false, std::memory_order_seq_cst);
#if !defined(__SANITIZE_THREAD__)
    std::atomic_thread_fence(std::memory_order_seq_cst);
#endif
    if (!holder_.load(std::memory_order_acquire) || gated_.load(std::memory_order_acquire) ||
        backlog_.load(std::memory_order_acquire) || !has_export_work())
      return;
    if (export_busy_.exchange(true, std::memory_order_acquire)) return;
    if (!holder_.load(std::memory_order_acquire)) {  // handed over meanwhile
      export_busy_.store(false, std::memory_order_release);
      return;
    }
    drain();
  }
}

// One attempt, on an engine thread (the engine comes back in 10 ms: one reader that lags never
// holds up the other topics, the import pump or the control thread). A publishing thread never
// retries a stash: it would wait as long as an unreachable reader stays matched (until its
// lease ends, 10 s and more), and a process could not even end.
bool Bridge::flush_stash() noexcept {
  if (!backlog_.load(std::memory_order_acquire)) return true;
  if (!t_engine_thread && !stop_.load(std::memory_order_relaxed)) return false;
  const net::BodyWriter writer{[](void* c, std::span<std::byte> body) {
                                 const auto& s = *static_cast<const std::vector<std::byte>*>(c);
                                 std::memcpy(body.data(), s.data(), body.size());
                               },
                               &stash_};
  for (;;) {
    auto ok = endpoint_->write(stash_.size(), writer);
    if (ok) {
      state().exported.fetch_add(1, std::memory_order_relaxed);
      break;
    }
    if (ok.error().code() != Errc::Timeout) {
      state().dropped.fetch_add(1, std::memory_order_relaxed);
      break;
    }
    ++write_retries_;
    if (stop_.load(std::memory_order_relaxed)) {
      state().dropped.fetch_add(1, std::memory_order_relaxed);  // closing: it will not go out
      gave_up_ = true;
      break;
    }
    if (t_engine_thread) {
      engine_->recheck(*this, false);
      return false;
    }
  }
  state().inflight.store(0, std::memory_order_relaxed);
  backlog_.store(false, std::memory_order_release);
  return true;
}

// --- the egress budget (the rest is bridge_budget.cpp) -----------------------------------

// The message the budget held back: sent when the budget allows (the engine comes back every
// 10 ms meanwhile). True when nothing waits any more.
bool Bridge::flush_latest() noexcept {
  if (!has_latest_) return true;
  if (!admit(now_ns(), latest_.size())) {
    engine_->recheck(*this, false);
    return false;
  }
  const net::BodyWriter writer{[](void* c, std::span<std::byte> body) {
                                 auto* self = static_cast<Bridge*>(c);
                                 std::memcpy(body.data(), self->latest_.data(), body.size());
                                 if (self->loopback_) self->ledger_.add(body_hash(body));
                               },
                               this};
  auto ok = endpoint_->write(latest_.size(), writer);
  if (!ok && ok.error().code() == Errc::Timeout && !stop_.load(std::memory_order_relaxed)) {
    budget_.any_sent = false;  // not sent after all: its turn again at the next look
    engine_->recheck(*this, false);
    return false;
  }
  has_latest_ = false;
  if (ok) {
    state().exported.fetch_add(1, std::memory_order_relaxed);
    engine_->send_worked();
  } else {
    state().dropped.fetch_add(1, std::memory_order_relaxed);
    if (ok.error().code() == Errc::Io) engine_->send_failed(core_.name, ok.error());
  }
  return true;
}

void Bridge::drain() noexcept {
  // Under export_busy_: a hand-over (control thread) sets holder_ false while it holds it, then
  // closes the endpoint; an exporter that got export_busy_ after that exports nothing.
  if (!holder_.load(std::memory_order_acquire)) return;
  const horus::detail::ExportSink sink{this, [](void* c, const void* msg) { return static_cast<Bridge*>(c)->send(msg); }};
  try {
    if (!flush_stash()) return;
    (void)flush_latest();
    // From before a message is read (the read moves the cursor a successor adopts) until the
    // transport took the last one: a holder killed in between cost at most one message, which
    // its successor counts (maybe sent, never twice).
    state().inflight.store(1, std::memory_order_relaxed);
    while (!backlog_.load(std::memory_order_relaxed) && port_->export_pending(port_->lane(), sink) != 0) {
    }
    if (!backlog_.load(std::memory_order_relaxed)) state().inflight.store(0, std::memory_order_relaxed);
  } catch (const std::exception& e) {
    log().error("topic '{}': exporting to {} failed: {}", core_.name, info_.name, e.what());
  }
  if (const std::uint64_t lost = port_->export_lost(); lost > export_lost_seen_) {
    state().dropped.fetch_add(lost - export_lost_seen_, std::memory_order_relaxed);
    export_lost_seen_ = lost;
  }
}

bool Bridge::send(const void* msg) {
  auto report = [&](const Error& error) {
    state().dropped.fetch_add(1, std::memory_order_relaxed);
    if (error.code() == Errc::Io) {  // the network: once for the transport, not per topic
      engine_->send_failed(core_.name, error);
      return true;
    }
    if (++send_failures_ == 1 || send_failures_ % 1024 == 0)
      log().error("topic '{}': the {} backend did not send a {} sample: {} ({} so far; counted in "
                  "dropped_count())",
                  core_.name, info_.name, core_.type_name, error.message(), send_failures_);
    return true;  // go on with the next message
  };
  // Closing, and a reliable write timed out: the readers do not take (a link is down); what is
  // left is counted, not written (one bounded wait per message could hold the close for minutes).
  if (gave_up_) {
    state().dropped.fetch_add(1, std::memory_order_relaxed);
    return true;
  }
  auto n = encoded_size(msg);
  if (!n) return report(n.error());
  if (budgeted()) [[unlikely]] {
    if (has_latest_) {  // a newer message: the one the budget held back is not sent
      has_latest_ = false;
      budget_drop();
    }
    if (!admit(now_ns(), *n)) {
      latest_.resize(*n);
      encode(msg, latest_);
      has_latest_ = true;
      engine_->recheck(*this, false);
      return true;  // read on: a newer message replaces it
    }
  }
  struct Context {
    Bridge* self;
    const void* msg;
    bool echo;  // our sample may come back: note it in the ledger
  } ctx{this, msg,
        loopback_ && (receiving_.load(std::memory_order_relaxed) ||
                      now_ns() - paused_at_ns_.load(std::memory_order_relaxed) <
                          std::chrono::duration_cast<Clock::duration>(kEchoTtl).count())};
  const net::BodyWriter writer{[](void* c, std::span<std::byte> body) {
                                 const auto& x = *static_cast<const Context*>(c);
                                 x.self->encode(x.msg, body);
                                 if (x.echo) x.self->ledger_.add(body_hash(body));
                               },
                               &ctx};
  auto ok = endpoint_->write(*n, writer);
  // Reliable: a writer that timed out waiting for its readers to catch up (its own bounded
  // wait, 100 ms) keeps the message (back-pressure, not a loss): it waits in the stash, this
  // topic exports nothing else until it went out, and the engine's export thread tries again
  // every 10 ms (flush_stash). Meanwhile the host's ring fills up, so that send_blocking and
  // try_send feel the back-pressure as they do locally; a publishing thread never waits more
  // than one bounded write for a reader that may be gone (a link down).
  if (!ok && ok.error().code() == Errc::Timeout && qos_.reliability == net::Reliability::Reliable &&
      !stop_.load(std::memory_order_relaxed)) {
    ++write_retries_;
    stash_.resize(*n);
    encode(msg, stash_);
    backlog_.store(true, std::memory_order_release);
    engine_->recheck(*this, false);
    return false;  // stop after this message: it is in the stash
  }
  if (!ok && ok.error().code() == Errc::Timeout && stop_.load(std::memory_order_relaxed)) gave_up_ = true;
  if (!ok) [[unlikely]]
    return report(ok.error());
  state().exported.fetch_add(1, std::memory_order_relaxed);
  engine_->send_worked();
  return true;
}

}  // namespace horus::fleet::detail
