// The bridge of one fleet topic in one process (bridge.hpp: holder, receiving, takeover).
#include "bridge.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "horus/detail/bridge_port.hpp"
#include "horus/environment.hpp"
#include "horus/log.hpp"
#include "horus/shm/doorbell.hpp"

namespace horus::fleet::detail {

using horus::detail::log;

namespace {
constexpr auto kMatchWait = std::chrono::seconds(1);          // a successor waits for the readers
constexpr auto kImportWait = std::chrono::milliseconds(100);  // a reliable import holds samples for room
constexpr auto kEchoTtl = std::chrono::seconds(2);            // how long our own sample may take to come back
// The hand-over (bridge.hpp):
constexpr auto kQuiet = std::chrono::milliseconds(200);      // no import for this long before a hand-over
constexpr auto kAskLook = std::chrono::milliseconds(200);    // a publishing watcher looks this often
constexpr auto kAskBackOff = std::chrono::seconds(5);        // after a refusal (doubles, up to kAskBackOffMax)
constexpr auto kAskBackOffMax = std::chrono::seconds(60);
constexpr auto kAskPoll = std::chrono::milliseconds(1);      // matching, asked: how often it looks
constexpr auto kAskWait = std::chrono::seconds(1);           // how long the holder may take to answer
constexpr auto kAcceptedWait = std::chrono::seconds(3);      // accepted: how long the closing may take
constexpr auto kRingAgain = std::chrono::milliseconds(50);   // ring the holder again (it was exporting)
constexpr auto kSettle = std::chrono::milliseconds(20);      // closed: what it sent reaches the asker first
// The holder accepted (the `handover` word's low half carries the asker's participant + 1, far
// below this bit): it has stopped exporting and closes its endpoint; the asker waits for the claim.
constexpr std::uint64_t kAccepted = std::uint64_t{1} << 31;

std::atomic<int> g_network_pid{0};  // the process that created this process's transports

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

std::int64_t now_ns() noexcept { return Clock::now().time_since_epoch().count(); }
}  // namespace

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
Result<bool> may_bridge_from_environment() { return may_bridge(Environment::read().bridge); }

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
                                                                 const net::Qos& qos, const TopicOptions& options) {
  const auto* info = net::find_transport(core.backend.transport());
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
  auto may = may_bridge_from_environment();
  if (!may) return std::unexpected(std::move(may.error()));
  if (!*may) return std::unique_ptr<horus::detail::NetworkLink>(new PassiveLink(core, qos));  // HORUS_BRIDGE=0
  auto wire = info->wire_name(core.name);
  if (!wire) return std::unexpected(std::move(wire.error()));
  auto engine = Engine::of(*info);  // the transport reads its own settings (HORUS_DOMAIN_ID, HORUS_LCM_URL)
  if (!engine) return std::unexpected(std::move(engine.error()));
  g_network_pid.store(horus::detail::current_pid());
  auto transport = (*engine)->transport_for(core.name);
  if (!transport) return std::unexpected(std::move(transport.error()));
  std::unique_ptr<Bridge> b(new Bridge(core, ops, qos, std::move(*engine), std::move(*transport)));
  b->wire_topic_ = std::move(*wire);
  b->set_budget(options);
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
  if (!core.name.starts_with(kFleetTopicPrefix)) b->presence_ = acquire_presence(std::string(info->name));
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
    // goes out, or a volatile reader would miss it (bounded: a reader may have left). The
    // control thread opens the gate (control()).
    gate_readers_ = readers_before;
    gate_until_ = Clock::now() + kMatchWait;
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
  spec.type_name = core_.type_name;
  spec.type_hash = core_.type_hash;
  spec.qos = qos_;
  spec.max_message_bytes = core_.pool ? core_.pool.slot_bytes() : core_.ring.payload_size();
  receiving_.store(receive, std::memory_order_relaxed);
  spec.receive = receive;
  auto endpoint = transport_->open(spec, *this);
  if (!endpoint) return std::unexpected(std::move(endpoint.error()));
  std::lock_guard lock(endpoint_mutex_);
  endpoint_ = std::move(*endpoint);
  return {};
}

void Bridge::close_endpoint() noexcept {
  std::lock_guard receiving(receiving_mutex_);  // no opening handle is inside update_receiving()
  std::lock_guard lock(endpoint_mutex_);        // the import pump is not inside take_held()
  endpoint_ready_.store(false, std::memory_order_release);
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
  if (holder_.load(std::memory_order_acquire) && state().handover.load(std::memory_order_acquire) != 0) {
    const auto at = hand_over(now);
    if (!holder_.load(std::memory_order_acquire)) return at;  // accepted: handing_to_ from here on
    if (at != Clock::time_point::max()) return at;
  }
  if (handing_to_ != 0) {
    if (now < handing_at_) return handing_at_;
    finish_hand_over();
  }
  if (holder_.load(std::memory_order_acquire)) {
    if (gated_.load(std::memory_order_acquire)) {
      std::uint32_t matched = 0;
      try {
        matched = endpoint_->matched_subscribers();
      } catch (...) {
      }
      if (matched < gate_readers_ && now < gate_until_) return now + std::chrono::milliseconds(1);
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
  if (handed || ask_ != Ask::Idle) {
    ask_ = Ask::Idle;
    ask_backoff_ = kAskBackOff;
    for (std::uint64_t asked : {mine | kAccepted, mine}) {
      std::uint64_t w = asked;
      state().handover.compare_exchange_strong(w, 0, std::memory_order_acq_rel);
    }
  }
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

// --- the hand-over (bridge.hpp): the bridge follows the host's publisher ------------------------


// A user thread, at a handle's first send: the engine's control thread takes it from here.
// Not for the fleet layer's own topics, nor transient-local ones (a writer's history is what a
// late joiner gets: it must not go with a hand-over).
void Bridge::on_publisher() noexcept {
  if (horus::detail::current_pid() != creator_pid_ || core_.name.starts_with(kFleetTopicPrefix) ||
      qos_.durability == net::Durability::TransientLocal)
    return;
  if (holder_.load(std::memory_order_acquire) || publishes_.exchange(true, std::memory_order_acq_rel)) return;
  try {
    engine_->look(*this);
  } catch (...) {  // out of memory: the bridge stays where it is
  }
}

// Whether process `pid` owns a publisher lane of the topic (`skip_import`: the bridge's import
// lane, which the holder owns, not counted).
bool Bridge::owns_lane(pid_t pid, bool skip_import) const noexcept {
  const std::uint32_t hwm = std::min(core_.ring.header().lane_hwm.load(std::memory_order_acquire), shm::kMaxPublishers);
  const std::uint64_t import_token = state().import_token.load(std::memory_order_acquire);
  for (std::uint32_t l = 0; l < hwm; ++l) {
    const std::uint64_t token = core_.ring.lane(l).owner.load(std::memory_order_acquire);
    if (token == 0 || shm::token_pid(token) != pid) continue;
    if (skip_import && token == import_token) continue;
    return true;
  }
  return false;
}

// The control thread, for a watcher whose process publishes on the topic: looks whether the
// holder publishes too and whether imports are quiet, opens this process's endpoint and waits
// until it matched what the holder's did (and the holder's matched it), then asks (the segment's
// `handover` word) and rings the holder's engine (the bridge class of the doorbell). The holder
// accepts or refuses in the word, then writes our word into the claim, which control() sees as
// Ours. Returns when it wants to be called again.
Clock::time_point Bridge::handover_step(Clock::time_point now, std::uint64_t owner) noexcept {
  const std::uint64_t mine = segment().bridge_word();
  const bool holder_alive = owner != 0 && segment().bridge_word_alive(owner);
  const bool discovery = info_.format != net::WireFormat::Lcm;  // LCM matches nothing: counts stay 0
  switch (ask_) {
    case Ask::Idle: {
      if (now < ask_next_) return ask_next_;
      ask_next_ = now + kAskLook;
      if (!owns_lane(::getpid(), false)) {  // its publishers closed: nothing to follow
        publishes_.store(false, std::memory_order_release);
        return Clock::time_point::max();
      }
      if (!holder_alive || mine == 0) return ask_next_;  // nobody holds it: the claim takes it
      if (owns_lane(static_cast<pid_t>(owner >> 32), true)) {
        ask_next_ = now + kAskBackOff;  // the holder publishes too: it keeps the bridge
        return ask_next_;
      }
      const std::uint64_t imported = state().imported.load(std::memory_order_relaxed);
      if (imported != quiet_imported_) {
        quiet_imported_ = imported;
        quiet_since_ = now;
        return ask_next_;
      }
      if (now - quiet_since_ < kQuiet) return ask_next_;
      ask_readers_ = state().matched_subscribers.load(std::memory_order_relaxed);
      if (auto ok = open_endpoint(true); !ok) {
        log().warn("topic '{}': this process publishes on it but could not open its {} endpoint to take the "
                   "host's bridge over ({}); the bridge stays with pid {}",
                   core_.name, info_.name, ok.error().message(), owner >> 32);
        ask_next_ = now + kAskBackOffMax;
        return ask_next_;
      }
      ask_ = Ask::Matching;
      ask_until_ = now + kMatchWait;
      return now + kAskPoll;
    }
    case Ask::Matching: {
      if (!holder_alive) {
        cancel_ask(false);
        return now;
      }
      std::uint32_t readers = 0, writers = 0;
      try {
        readers = endpoint_->matched_subscribers();
        writers = endpoint_->matched_publishers();
      } catch (...) {
      }
      // DDS: the holder's endpoint matched ours (its count of readers grew) and ours matched as
      // many as the holder's (each counts the other): every remote endpoint matched ours too.
      const std::uint32_t holder_readers = state().matched_subscribers.load(std::memory_order_relaxed);
      const bool matched = !discovery || (holder_readers > ask_readers_ && readers >= holder_readers &&
                                          writers >= state().matched_publishers.load(std::memory_order_relaxed));
      if (!matched && now < ask_until_) return now + kAskPoll;
      std::uint64_t other = 0;
      if (!state().handover.compare_exchange_strong(other, mine, std::memory_order_acq_rel)) {
        if (segment().bridge_word_alive(other & ~kAccepted) && (other & ~kAccepted) != mine) {
          cancel_ask(false);  // another process asks: one at a time
          return ask_next_;
        }
        if (!state().handover.compare_exchange_strong(other, mine, std::memory_order_acq_rel)) {
          cancel_ask(false);
          return ask_next_;
        }
      }
      prematched_ = matched;  // else the gate waits for the readers, as after a takeover
      ask_ = Ask::Asked;
      ask_until_ = now + kAskWait;
      rang_at_ = now;
      (void)core_.ring.wake_waiters(shm::Doorbell::kArmedBridge);
      return now + kAskPoll;
    }
    case Ask::Asked: {
      const std::uint64_t word = state().handover.load(std::memory_order_acquire);
      if (word == (mine | kAccepted)) {  // the holder closes its endpoint; the claim comes next
        if (now < ask_until_ + kAcceptedWait) return now + kAskPoll;
      } else if (word == mine && holder_alive && now < ask_until_) {
        if (now - rang_at_ >= kRingAgain) {  // the holder was exporting: ring again
          rang_at_ = now;
          (void)core_.ring.wake_waiters(shm::Doorbell::kArmedBridge);
        }
        return now + kAskPoll;
      }
      log().debug("topic '{}': the host's bridge stays with pid {} (it did not hand it over)", core_.name,
                  owner >> 32);
      cancel_ask(true);
      return ask_next_;
    }
  }
  return Clock::time_point::max();
}

// Gives up asking: the request word (unless accepted) and this process's endpoint go; looks again
// later, after a longer while each time the holder refused (`refused`).
void Bridge::cancel_ask(bool refused) noexcept {
  if (std::uint64_t mine = segment().bridge_word(); mine != 0)
    state().handover.compare_exchange_strong(mine, 0, std::memory_order_acq_rel);
  close_endpoint();
  prematched_ = false;
  ask_ = Ask::Idle;
  ask_backoff_ = refused ? std::min<Clock::duration>(ask_backoff_ * 2, kAskBackOffMax) : ask_backoff_;
  ask_next_ = Clock::now() + ask_backoff_;
}

// The holder's control thread, asked for the bridge (service() saw the word): refuses (clears the
// word: the asker learns at once) unless this process publishes nothing on the topic, the asker
// lives, the import was quiet for kQuiet and nothing waits here (the gate, a stashed reliable
// write, the budget's newest message, samples the transport holds). Accepting, it stops exporting
// (what it did not export stays in the ring for the asker, who adopts the entry), closes its
// endpoint and, kSettle later (what it sent reaches the asker's reader before the asker imports),
// writes the asker's word into the claim (control(), handing_to_). Returns when to look again.
Clock::time_point Bridge::hand_over(Clock::time_point now) noexcept {
  const std::uint64_t word = state().handover.load(std::memory_order_acquire);
  const std::uint64_t to = word & ~kAccepted;
  const std::uint64_t mine = segment().bridge_word();
  auto refuse = [&] {
    std::uint64_t w = word;
    state().handover.compare_exchange_strong(w, 0, std::memory_order_acq_rel);
    return Clock::time_point::max();
  };
  if (to == 0 || to == mine) return Clock::time_point::max();
  // Accepted by a holder before us, whose asker did not take the claim (it died): stale.
  if ((word & kAccepted) != 0 || !segment().bridge_word_alive(to) || qos_.durability == net::Durability::TransientLocal ||
      owns_lane(::getpid(), true) ||
      now_ns() - last_import_ns_.load(std::memory_order_relaxed) <
          std::chrono::duration_cast<Clock::duration>(kQuiet).count())
    return refuse();
  if (export_busy_.exchange(true, std::memory_order_acquire)) return now + kAskPoll;  // exporting now
  if (gated_.load(std::memory_order_acquire) || backlog_.load(std::memory_order_acquire) || has_latest_ ||
      held_.load(std::memory_order_acquire)) {
    release_export();
    return refuse();
  }
  std::uint64_t w = word;
  if (!state().handover.compare_exchange_strong(w, to | kAccepted, std::memory_order_acq_rel)) {
    release_export();
    return Clock::time_point::max();
  }
  core_.inline_export.active.store(false, std::memory_order_release);
  holder_.store(false, std::memory_order_release);  // no export from here on (export_inline, release_export)
  export_busy_.store(false, std::memory_order_release);
  if (attached_.exchange(false))
    shm::engine_leave(core_.ring.doorbell(), core_.ring.subscriber(port_->entry()).waiting, forward_);
  close_endpoint();
  // The entry and the lane stay as recorded in the segment for the asker, who adopts them (their
  // owner tokens become its own). The port stays too: a publishing thread of this process that
  // raced the hand-over may still look at it (release_export), and finds it no longer owns them.
  port_stale_ = true;
  gated_.store(false, std::memory_order_relaxed);
  held_.store(false, std::memory_order_relaxed);
  handing_to_ = to;
  handing_at_ = Clock::now() + kSettle;
  return handing_at_;
}

// The control thread, kSettle after hand_over() closed the endpoint: the claim goes to the asker.
void Bridge::finish_hand_over() noexcept {
  const std::uint64_t to = std::exchange(handing_to_, 0);
  const bool alive = segment().bridge_word_alive(to);
  if (!segment().transfer_bridge(to)) segment().release_bridge();
  if (!alive) {  // it died meanwhile: nobody clears its word; a watcher takes the claim over
    std::uint64_t w = to | kAccepted;
    state().handover.compare_exchange_strong(w, 0, std::memory_order_acq_rel);
  }
  log().info("topic '{}': this process (pid {}) handed the host's bridge to {} over to pid {}, which publishes on it",
             core_.name, ::getpid(), info_.name, to >> 32);
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
  auto n = ops_.encoded_size(format_, msg);
  if (!n) return report(n.error());
  if (budgeted()) [[unlikely]] {
    if (has_latest_) {  // a newer message: the one the budget held back is not sent
      has_latest_ = false;
      budget_drop();
    }
    if (!admit(now_ns(), *n)) {
      latest_.resize(*n);
      ops_.encode(format_, msg, latest_);
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
                                 x.self->ops_.encode(x.self->format_, x.msg, body);
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
    ops_.encode(format_, msg, stash_);
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

// --- receiving -------------------------------------------------------------------------------

void Bridge::on_sample(const net::Sample& sample) {
  if (!holder_.load(std::memory_order_acquire)) [[unlikely]] {
    // An endpoint opened for a hand-over: the holder imports until it hands the bridge over.
    // A sample that comes after that and before this process holds it is not imported: counted.
    if (state().owner.load(std::memory_order_acquire) == segment().bridge_word())
      state().dropped.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (loopback_ && ledger_.consume(body_hash(sample.body))) return;  // our own, back
  if (!port_->deliver(format_, sample)) return;
  last_import_ns_.store(now_ns(), std::memory_order_relaxed);
  state().imported.fetch_add(1, std::memory_order_relaxed);
  // The import wakes the host's handles, not the export (it skips these messages); once they
  // fill half the ring, let the engine pass over them, so that the export cursor never falls a
  // ring behind (that would count as losses nobody had).
  // Through the doorbell's bridge class: one wake-up per time the engine armed it, not per sample.
  if (import_lag() > core_.ring.capacity() / 2) core_.ring.wake_waiters(shm::Doorbell::kArmedBridge);
}

std::uint64_t Bridge::import_lag() const noexcept {
  const std::uint32_t lane = port_->lane();
  if (lane >= shm::kMaxPublishers || !port_->has_entry()) return 0;
  const std::uint64_t head = core_.ring.lane(lane).head.load(std::memory_order_acquire);
  const std::uint64_t seen = core_.ring.subscriber(port_->entry()).cursor[lane].load(std::memory_order_relaxed);
  return head > seen ? head - seen : 0;
}

// Reliable topics on a transport that holds samples (DDS): the transport takes no more than the
// host's subscribers have room for, and the rest waits in its reader, whose flow control slows
// the sending host, instead of overwriting. The transport's thread never blocks (it serves every
// topic and the fleet's heartbeats): the engine pumps the held samples when room appears. A
// subscriber that leaves the lane full for kImportWait is stuck (stopped, in a debugger): then
// its oldest messages are overwritten (counted in its dropped_count) until it reads again.
std::size_t Bridge::room() {
  if (!hold_ || !holder_.load(std::memory_order_acquire)) return SIZE_MAX;
  const std::size_t r = port_->import_room();
  if (r > 0) {  // the subscribers read: not stuck
    stalled_.store(false, std::memory_order_relaxed);
    held_since_ns_.store(0, std::memory_order_relaxed);
    return r;
  }
  if (stalled_.load(std::memory_order_relaxed)) return SIZE_MAX;
  if (held_since_ns_.load(std::memory_order_relaxed) == 0) held_since_ns_.store(now_ns(), std::memory_order_relaxed);
  if (!held_.exchange(true, std::memory_order_acq_rel)) engine_->pump(*this);
  return 0;
}

bool Bridge::pump_held() noexcept {
  const std::int64_t since_ns = held_since_ns_.load(std::memory_order_relaxed);
  const auto since = Clock::time_point(Clock::duration(since_ns));
  if (since_ns != 0 && Clock::now() - since > kImportWait && !stalled_.exchange(true, std::memory_order_relaxed)) {
    const std::uint64_t n = ++import_stalls_;
    if (n == 1 || n % 64 == 0)
      log().warn("topic '{}': a subscriber on this host has not read for {} ms; the bridge stops holding the {} "
                 "samples back for it and overwrites its oldest messages (counted in its dropped_count()) until it "
                 "reads again ({} time(s) so far)",
                 core_.name, std::chrono::duration_cast<std::chrono::milliseconds>(kImportWait).count(), info_.name,
                 n);
  }
  std::lock_guard lock(endpoint_mutex_);
  if (!endpoint_)  // not open yet: try again (a bridge handed over has nothing to pump)
    return holder_.load(std::memory_order_acquire) || becoming_.load(std::memory_order_acquire);
  held_.store(false, std::memory_order_release);  // room() sets it again if it must hold on
  endpoint_->take_held();
  return held_.load(std::memory_order_acquire);
}

void Bridge::on_lost(std::uint64_t count) {
  if (!holder_.load(std::memory_order_acquire)) return;  // a hand-over's endpoint: the holder counts
  const auto before = state().dropped.fetch_add(count, std::memory_order_relaxed);
  // Log the first loss, then at most once per 1024 more (the count is in dropped_count()).
  if (before == 0 || before / 1024 != (before + count) / 1024)
    log().warn("topic '{}': the {} backend lost {} message(s) or datagram(s) ({} so far on this host; they "
               "count in dropped_count())",
               core_.name, info_.name, count, before + count);
}

void Bridge::on_matched() {
  // The transport's thread: the export thread asks the endpoint and publishes the counts.
  matches_changed_.store(true, std::memory_order_release);
  engine_->notify(*this);
}

void Bridge::on_error(std::string_view message) {
  const auto n = errors_.fetch_add(1, std::memory_order_relaxed) + 1;
  if (n <= 16 || n % 1024 == 0) log().error("{} [{}]", message, info_.name);
}

// The host's subscribing handles, the holder's own entry left out.
std::uint32_t Bridge::host_subscribers() const noexcept {
  const std::uint32_t n = core_.ring.subscriber_count();
  return n - (n != 0 && port_ && port_->has_entry() ? 1u : 0u);
}

// Stops or resumes receiving as the host's subscribers come and go: the engine, and a handle
// of the holding process that subscribes (its open() returns once the bridge receives; a
// handle of another process rings the doorbell, which wakes the engine to resume at once).
void Bridge::update_receiving() noexcept {
  std::lock_guard lock(receiving_mutex_);
  if (!endpoint_ready_.load(std::memory_order_acquire)) return;
  const bool want = host_subscribers() != 0;
  if (want == receiving_.load(std::memory_order_relaxed)) return;
  receiving_.store(want, std::memory_order_relaxed);
  if (!want) paused_at_ns_.store(now_ns(), std::memory_order_relaxed);
  endpoint_->set_receiving(want);
}

void Bridge::publish_matches() noexcept {
  if (!endpoint_ready_.load(std::memory_order_acquire)) return;
  std::lock_guard lock(endpoint_mutex_);  // a hand-over closes it on the control thread
  if (!endpoint_ || !holder_.load(std::memory_order_acquire)) return;
  try {
    state().matched_publishers.store(endpoint_->matched_publishers(), std::memory_order_relaxed);
    state().matched_subscribers.store(endpoint_->matched_subscribers(), std::memory_order_relaxed);
  } catch (...) {
  }
}

// --- reports -----------------------------------------------------------------------------------

std::uint64_t Bridge::dropped() const noexcept { return state().dropped.load(std::memory_order_relaxed); }

// Remote writers (readers) the host's bridge matched: asked of the endpoint in the holding
// process, read from the segment (published by the holder's engine) in the others.
std::uint32_t Bridge::remote(bool writers) const noexcept {
  if (endpoint_ready_.load(std::memory_order_acquire)) {
    std::lock_guard lock(endpoint_mutex_);  // a hand-over closes it on the export thread
    if (endpoint_) try {
      return writers ? endpoint_->matched_publishers() : endpoint_->matched_subscribers();
    } catch (...) {
    }
  }
  return (writers ? state().matched_publishers : state().matched_subscribers).load(std::memory_order_relaxed);
}

}  // namespace horus::fleet::detail
