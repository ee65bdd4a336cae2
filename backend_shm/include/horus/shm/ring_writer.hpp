// RingWriter<T>: the sending hot path. One writer owns one lane (claimed on first use), so a
// send is a slot write (seqlock_slot.hpp), a store of the lane's head and a load of the
// doorbell's waiter count: no lock, no read-modify-write, no syscall (unless a receiver
// sleeps: doorbell.hpp). A full lane overwrites its oldest slot; has_space() tells
// a caller that wants to wait instead (the subscribers' cursors, ring_control.hpp).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>

#include "horus/shm/ring_control.hpp"
#include "horus/shm/ring_layout.hpp"
#include "horus/shm/seqlock_slot.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

/// The sending side of one handle: owns a lane once it has sent. Not thread-safe.
/// T is a trivially copyable message, or ByteMessage for serialized messages (write_bytes).
template <class T>
class RingWriter {
 public:
  static constexpr bool kBytes = std::is_same_v<T, ByteMessage>;

  RingWriter() = default;
  RingWriter(Ring ring, std::uint64_t token) noexcept : ring_(ring), token_(token), stride_(ring.stride()) {}
  RingWriter(RingWriter&& o) noexcept { *this = std::move(o); }
  RingWriter& operator=(RingWriter&& o) noexcept {
    if (this != &o) {
      release();
      ring_ = o.ring_;
      token_ = o.token_;
      lane_ = o.lane_;
      head_ = o.head_;
      mask_ = o.mask_;
      slots_ = o.slots_;
      lane_head_ = o.lane_head_;
      state_ = o.state_;
      space_limit_ = o.space_limit_;
      claim_head_ = o.claim_head_;
      sent_before_ = o.sent_before_;
      stride_ = o.stride_;
      wake_classes_ = o.wake_classes_;
      inline_export_ = o.inline_export_;
      observed_ = o.observed_;
      expect_ = o.expect_;
      o.lane_ = kNoLane;
      o.slots_ = nullptr;
    }
    return *this;
  }
  ~RingWriter() { release(); }

  bool has_lane() const noexcept { return slots_ != nullptr; }
  /// A fleet bridge's import writes what came from the network: its sends wake the handles
  /// blocked on the topic, not the bridge's own export thread (doorbell.hpp).
  void wake_readers_only() noexcept { wake_classes_ = Doorbell::kArmedReader; }
  /// A fleet topic's handle: sends export inline while `e->active` (doorbell.hpp, InlineExport).
  void set_inline_export(InlineExport* e) noexcept { inline_export_ = e; }
  /// A handle that looks at what it sent (a deadline, verbose lines: api/'s Watch): every
  /// write() then returns false, through the branch a send takes anyway when receivers wait.
  /// An unobserved writer's fast path compares the doorbell's state with one value, as before.
  void observe(bool on) noexcept {
    observed_ = on;
    expect_ = expected_state();
  }
  /// The token this writer claims its lane with.
  std::uint64_t token() const noexcept { return token_; }
  /// The lane this writer owns (when has_lane()).
  std::uint32_t lane() const noexcept { return lane_; }
  /// The lane's next sequence number (messages ever written to it).
  std::uint64_t head() const noexcept { return head_; }
  /// Claims a lane; false when every lane of the topic is in use.
  bool ensure_lane() noexcept {
    if (has_lane()) return true;
    auto lane = ring_.claim_lane(token_);
    if (!lane) return false;
    bind(*lane);
    return true;
  }

  /// Takes over lane `lane`, held by `from` (a bridge that died or left): the lane keeps its
  /// index and sequence, so one origin's messages stay in one lane. False when it has another
  /// owner by then.
  bool adopt(std::uint32_t lane, std::uint64_t from) noexcept {
    release();
    if (!ring_.adopt_lane(lane, from, token_)) return false;
    bind(lane);
    return true;
  }

  /// Lets go of the lane without freeing it: a successor adopts it.
  void leave() noexcept {
    if (has_lane()) sent_before_ += head_ - claim_head_;
    lane_ = kNoLane;
    slots_ = nullptr;
    expect_ = expected_state();
  }

  /// Publishes; overwrites the oldest slot of the lane when it is full. Requires ensure_lane().
  /// False only for an observed writer (observe()): the message is sent either way.
  [[gnu::always_inline]] bool write(const T& msg) noexcept
    requires(!kBytes)
  {
    return commit(msg);
  }

  /// Publishes an encoded message of at most max_serialized_size(payload_size) bytes; false
  /// only for an observed writer (the message is sent either way).
  bool write_bytes(std::span<const std::byte> msg) noexcept
    requires kBytes
  {
    return commit(msg);
  }

  /// Largest encoded message write_bytes() accepts.
  std::uint32_t max_bytes() const noexcept { return max_serialized_size(ring_.payload_size()); }

  /// True if write() would not overwrite a message some other subscriber has not read. The limit
  /// is cached (like rigtorp's SPSCQueue caches the read index): subscribers' cursors are
  /// read again only when the cached limit is reached.
  bool has_space(std::uint64_t self_subscriber) noexcept {
    if (head_ < space_limit_) return true;
    space_limit_ = ring_.space_limit(lane_, head_, self_subscriber);
    return head_ < space_limit_;
  }

  /// How many messages fit before one would overwrite a message some subscriber (but
  /// `self_subscriber`) has not read; reads the cursors again when the cached limit is near.
  std::uint64_t room(std::uint64_t self_subscriber) noexcept {
    if (space_limit_ < head_ + 64) space_limit_ = ring_.space_limit(lane_, head_, self_subscriber);
    return space_limit_ > head_ ? space_limit_ - head_ : 0;
  }

  /// Reads the subscribers' cursors again (has_space() caches what it read).
  void refresh_space(std::uint64_t self_subscriber) noexcept {
    space_limit_ = ring_.space_limit(lane_, head_, self_subscriber);
  }

  /// After has_space() returned true: every subscriber (but the caller's own) has read the
  /// lane's messages below this sequence number.
  std::uint64_t read_by_all() const noexcept {
    const std::uint64_t cap = mask_ + 1;
    return space_limit_ >= cap ? space_limit_ - cap : 0;
  }

  /// Messages written through this writer (derived from the lane head: no counter on the hot path).
  std::uint64_t sent() const noexcept { return sent_before_ + (has_lane() ? head_ - claim_head_ : 0); }

  void release() noexcept {
    if (has_lane()) {
      sent_before_ += head_ - claim_head_;
      ring_.release_lane(lane_, token_);
    }
    lane_ = kNoLane;
    slots_ = nullptr;
    expect_ = expected_state();
  }

 private:
  static constexpr std::uint32_t kNoLane = ~0u;

  void bind(std::uint32_t lane) noexcept {
    lane_ = lane;
    lane_head_ = &ring_.lane(lane_).head;
    // The claim synchronised with the previous owner's release: this is its last head.
    head_ = lane_head_->load(std::memory_order_acquire);
    claim_head_ = head_;
    mask_ = ring_.capacity() - 1;
    state_ = &ring_.header().doorbell.state;
    space_limit_ = 0;
    slots_ = ring_.lane_slots(lane_);
    expect_ = expected_state();
  }

  // The doorbell state a send finds when it has nothing more to do: our lane as the latest-lane
  // hint and no waiter. An observed writer expects a state that never occurs (the waiters' half
  // all ones), so each of its sends takes after_commit.
  std::uint64_t expected_state() const noexcept { return observed_ ? ~std::uint64_t{0} : lane_; }

  std::size_t stride() const noexcept {
    if constexpr (kBytes) return stride_;
    else return slot_stride_for(sizeof(T));
  }

  template <class P>
  [[gnu::always_inline]] bool commit(const P& msg) noexcept {
    const std::uint64_t s = head_;
    write_slot(slots_ + (s & mask_) * stride(), s, msg);
    head_ = s + 1;
    // Release, after the slot's committing store: whoever sees the new head sees message s
    // committed. This writer never reads it back (head_ is its copy); see ring_control.hpp.
    lane_head_->store(s + 1, std::memory_order_release);
    // One relaxed load checks two things (doorbell.hpp): the latest-lane hint in the low half
    // (only written when it changes, so one publisher keeps the line shared and cheap) and the
    // blocked receivers in the high half (none: nothing more to do).
    const std::uint64_t state = state_->load(std::memory_order_relaxed);
    if (state != expect_) [[unlikely]]
      return after_commit(state);
    return true;
  }

  [[gnu::noinline]] bool after_commit(std::uint64_t state) noexcept {
    if (static_cast<std::uint32_t>(state) != lane_) {
      // Relaxed: a hint read_latest() checks against the heads (ring_control.hpp). A
      // compare-exchange, as waiters register in the high half meanwhile.
      while (!state_->compare_exchange_weak(state, (state & ~std::uint64_t{0xffff'ffff}) | lane_,
                                            std::memory_order_relaxed)) {
      }
    }
    if ((state >> 32) != 0) wake();
    return !observed_;
  }

  // Waiters registered: wake them if armed; a count that stays registered and unarmed for
  // kStaleCheck sends may be a waiter that died (doorbell.hpp).
  void wake() noexcept {
    InlineExport* const ex = inline_export_;
    if (ex != nullptr && ex->active.load(std::memory_order_acquire) && ex->generation == fork_generation()) {
      // This process bridges the topic: the readers first (their latency), then the network.
      const bool woke = ring_.wake_waiters(wake_classes_ & ~Doorbell::kArmedBridge);
      ex->run(ex->ctx);
      if (woke || ++unarmed_ < kStaleCheck) return;
    } else if (ring_.wake_waiters(wake_classes_) || ++unarmed_ < kStaleCheck) {
      return;
    }
    unarmed_ = 0;
    ring_.reap_dead_waiters();
  }

  // Hot fields first, read on every write.
  std::byte* slots_ = nullptr;  // this lane's slots; null until a lane is claimed
  std::uint64_t head_ = 0;
  std::uint64_t mask_ = 0;
  std::atomic<std::uint64_t>* lane_head_ = nullptr;
  std::atomic<std::uint64_t>* state_ = nullptr;  // the doorbell's state: latest lane, waiters
  std::uint32_t lane_ = kNoLane;
  std::uint64_t expect_ = kNoLane;  // expected_state(): what commit() compares the doorbell's state with
  std::uint64_t space_limit_ = 0;  // head values below this are known to have space
  std::uint64_t claim_head_ = 0;   // head when the lane was claimed
  std::uint32_t unarmed_ = 0;      // sends that found waiters but nobody armed (wake())
  std::uint32_t wake_classes_ = Doorbell::kArmedAll;  // the waiters a send wakes (doorbell.hpp)
  InlineExport* inline_export_ = nullptr;  // a fleet topic's, in process memory (doorbell.hpp)
  bool observed_ = false;          // observe()
  std::uint64_t sent_before_ = 0;  // messages sent through lanes released earlier
  Ring ring_;
  std::uint64_t token_ = 0;
  std::size_t stride_ = 0;  // used for ByteMessage only (fixed-size T: a constant)
};

}  // namespace horus::shm

HORUS_API_END
