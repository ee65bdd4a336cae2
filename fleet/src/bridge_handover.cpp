// The hand-over of a fleet topic's bridge (bridge.hpp): the bridge follows the host's publisher.
#include "bridge.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <optional>

#include "horus/detail/bridge_port.hpp"
#include "horus/log.hpp"
#include "horus/shm/doorbell.hpp"

namespace horus::fleet::detail {

using horus::detail::log;

namespace {
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
// Matched: the asker still waits discovery_settle() (bridge.hpp) before it asks. The holder's
// endpoint, which matched ours both ways, shows when our announcements went out and how long
// discovery takes on this machine now.
// The holder accepted (the `handover` word's low half carries the asker's participant + 1, far
// below this bit): it has stopped exporting and closes its endpoint; the asker waits for the claim.
constexpr std::uint64_t kAccepted = std::uint64_t{1} << 31;
}  // namespace

// --- the hand-over (bridge.hpp): the bridge follows the host's publisher ------------------------


// The control thread, first in control(): the holder answers a request (hand_over), and kSettle
// after accepting hands the claim over. A time: control() returns it (the hand-over is under way).
std::optional<Clock::time_point> Bridge::hand_over_due(Clock::time_point now) noexcept {
  if (holder_.load(std::memory_order_acquire) && state().handover.load(std::memory_order_acquire) != 0) {
    const auto at = hand_over(now);
    if (!holder_.load(std::memory_order_acquire)) return at;  // accepted: handing_to_ from here on
    if (at != Clock::time_point::max()) return at;
  }
  if (handing_to_ != 0) {
    if (now < handing_at_) return handing_at_;
    finish_hand_over();
  }
  return std::nullopt;
}

// The control thread: this process holds the bridge now (handed over, or claimed while it asked).
void Bridge::asked_done() noexcept {
  ask_ = Ask::Idle;
  ask_backoff_ = kAskBackOff;
  const std::uint64_t mine = segment().bridge_word();
  for (std::uint64_t asked : {mine | kAccepted, mine}) {
    std::uint64_t w = asked;
    state().handover.compare_exchange_strong(w, 0, std::memory_order_acq_rel);
  }
}

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
  switch (ask_) {
    case Ask::Idle: return ask_if_quiet(now, owner, holder_alive, mine);
    case Ask::Matching: return ask_once_matched(now, owner, holder_alive, mine);
    case Ask::Asked: return wait_for_answer(now, owner, holder_alive, mine);
  }
  return Clock::time_point::max();
}

// handover_step, Idle: whether to ask (this process publishes, the holder does not, the import
// was quiet for kQuiet); then this process's endpoint opens and the step is Matching.
Clock::time_point Bridge::ask_if_quiet(Clock::time_point now, std::uint64_t owner, bool holder_alive,
                                       std::uint64_t mine) noexcept {
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
  ask_writers_ = state().matched_publishers.load(std::memory_order_relaxed);
  ask_opened_ = now;
  ask_matched_ = {};
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

// handover_step, Matching: waits until this process's endpoint matched what the holder's did,
// and the settle; then asks (the `handover` word) and rings the holder: Asked.
Clock::time_point Bridge::ask_once_matched(Clock::time_point now, std::uint64_t owner, bool holder_alive,
                                           std::uint64_t mine) noexcept {
  const bool discovery = info_.format != net::WireFormat::Lcm;  // LCM matches nothing: counts stay 0
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
  // DDS: the holder's endpoint matched ours both ways (its counts of readers and of writers
  // grew) and ours matched as many as the holder's (each counts the other): every remote
  // endpoint matched ours too. Then the settle (kDiscoverySettle), for the remote readers.
  const std::uint32_t holder_readers = state().matched_subscribers.load(std::memory_order_relaxed);
  const std::uint32_t holder_writers = state().matched_publishers.load(std::memory_order_relaxed);
  const bool matched = !discovery || (holder_readers > ask_readers_ && holder_writers > ask_writers_ &&
                                      readers >= holder_readers && writers >= holder_writers);
  if (!matched) {
    if (now < ask_until_ && ask_matched_ == Clock::time_point{}) return now + kAskPoll;
    // Not matched within kMatchWait, or a remote endpoint went while settling: the holder
    // keeps the bridge (its export reaches every reader); look again later.
    log().debug("topic '{}': this process's {} endpoint did not match what the holder's did (readers {} of {}, "
                "writers {} of {}); the host's bridge stays with pid {} for now",
                core_.name, info_.name, readers, holder_readers, writers, holder_writers, owner >> 32);
    cancel_ask(false);
    return ask_next_;
  }
  if (discovery) {
    if (ask_matched_ == Clock::time_point{}) ask_matched_ = now;
    const auto settle = discovery_settle(ask_matched_ - ask_opened_);
    if (now < ask_matched_ + settle) return std::min(ask_matched_ + settle, now + std::chrono::milliseconds(10));
  }
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
  prematched_ = true;  // no gate: every reader matched ours
  ask_ = Ask::Asked;
  ask_until_ = now + kAskWait;
  rang_at_ = now;
  (void)core_.ring.wake_waiters(shm::Doorbell::kArmedBridge);
  return now + kAskPoll;
}

// handover_step, Asked: waits for the holder's answer (ringing it again while it was exporting);
// refused or not answered, gives up.
Clock::time_point Bridge::wait_for_answer(Clock::time_point now, std::uint64_t owner, bool holder_alive,
                                          std::uint64_t mine) noexcept {
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

}  // namespace horus::fleet::detail
