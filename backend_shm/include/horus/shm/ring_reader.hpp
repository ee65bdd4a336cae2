// RingReader<T>: the receiving hot path. One reader keeps a cursor per lane and reads the
// lanes in turn, so it sees every message of every publisher exactly once and in each
// publisher's order. A slot found overwritten (seqlock_slot.hpp) counts the messages lost and
// moves the cursor to the oldest one still there. Each cursor is published to the reader's
// subscriber entry for the writers' has_space() (ordering: ring_control.hpp).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <type_traits>
#include <utility>

#include "horus/shm/ring_control.hpp"
#include "horus/shm/ring_layout.hpp"
#include "horus/shm/seqlock_slot.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

/// The receiving side of one handle: a cursor per lane. Not thread-safe.
/// T is a trivially copyable message, or ByteMessage for serialized messages.
template <class T>
class RingReader {
 public:
  static constexpr bool kBytes = std::is_same_v<T, ByteMessage>;

  RingReader() = default;
  RingReader(Ring ring, std::uint64_t token) noexcept
      : slots_(ring.lane_slots(0)),
        mask_(ring.capacity() - 1),
        lane_bytes_(static_cast<std::size_t>(ring.capacity()) * ring.stride()),
        stride_(ring.stride()),
        lane_hwm_(&ring.header().lane_hwm),
        ring_(ring),
        token_(token) {}
  RingReader(RingReader&& o) noexcept { *this = std::move(o); }
  RingReader& operator=(RingReader&& o) noexcept {
    if (this != &o) {
      unsubscribe();
      slots_ = o.slots_;
      mask_ = o.mask_;
      lane_bytes_ = o.lane_bytes_;
      stride_ = o.stride_;
      lane_hwm_ = o.lane_hwm_;
      shared_cursor_ = o.shared_cursor_;
      next_lane_ = o.next_lane_;
      ring_ = o.ring_;
      token_ = o.token_;
      entry_ = o.entry_;
      lost_ = o.lost_;
      lost_before_ = o.lost_before_;
      skipped_ = o.skipped_;
      delivered_before_ = o.delivered_before_;
      corrupt_ = o.corrupt_;
      corrupt_before_ = o.corrupt_before_;
      std::copy(std::begin(o.cursor_), std::end(o.cursor_), std::begin(cursor_));
      std::copy(std::begin(o.start_), std::end(o.start_), std::begin(start_));
      o.entry_ = kNone;
      o.shared_cursor_ = nullptr;
    }
    return *this;
  }
  ~RingReader() { unsubscribe(); }

  bool subscribed() const noexcept { return shared_cursor_ != nullptr; }
  /// Starts receiving: every message sent from now on is delivered. False when the topic is full.
  bool subscribe() noexcept {
    if (subscribed()) return true;
    auto e = ring_.add_subscriber(token_);
    if (!e) return false;
    take_entry(*e);
    return true;
  }
  /// Takes over subscriber entry `entry`, held by `from` (a bridge that died or left): reading
  /// goes on where its previous owner stopped. False when the entry has another owner by then.
  bool adopt(std::uint32_t entry, std::uint64_t from) noexcept {
    unsubscribe();
    if (!ring_.adopt_subscriber(entry, from, token_)) return false;
    take_entry(entry);
    return true;
  }
  /// Lets go of the subscriber entry without freeing it: a successor adopts it.
  void leave() noexcept {
    if (subscribed()) delivered_before_ = delivered();
    entry_ = kNone;
    shared_cursor_ = nullptr;
  }
  /// Messages lost to overwrites that read() noticed (not those still unnoticed).
  std::uint64_t noticed_lost() const noexcept { return lost_before_ + lost_; }
  void unsubscribe() noexcept {
    if (subscribed()) {
      delivered_before_ = delivered();
      ring_.remove_subscriber(entry_, token_);
    }
    entry_ = kNone;
    shared_cursor_ = nullptr;
  }

  /// This reader's subscriber entry (when subscribed): what a blocked receiver registers with.
  std::uint32_t entry() const noexcept { return entry_; }
  /// The token of this reader's subscriber entry (0 when not subscribed).
  std::uint64_t token() const noexcept { return subscribed() ? token_ : 0; }

  /// Messages read() returned (derived from the cursors: no counter on the hot path).
  std::uint64_t delivered() const noexcept {
    if (!subscribed()) return delivered_before_;
    std::uint64_t advanced = 0;
    for (std::uint32_t l = 0; l < kMaxPublishers; ++l) advanced += cursor_[l] - start_[l];
    return delivered_before_ + advanced - lost_ - skipped_ - corrupt_;
  }

  /// Takes the next unread message (round-robin over publishers, FIFO within each).
  [[gnu::always_inline]] bool read(T& out) noexcept {
    // One publisher's lane (the common case): one compare, no turn kept (a store per read costs
    // 8% of a same-thread send+recv). When a second lane appears the turn starts where it was
    // (lane 0 at first, even just after a read of lane 0); from then on it goes round.
    if (lane_hwm_->load(std::memory_order_acquire) == 1) return read_lane(0, out);
    const std::uint32_t lanes = lane_count();
    std::uint32_t lane = next_lane_;
    for (std::uint32_t k = 0; k < lanes; ++k, ++lane) {
      if (lane >= lanes) lane = 0;
      if (read_lane(lane, out)) {
        next_lane_ = lane + 1;
        return true;
      }
    }
    return false;
  }

  /// read(), passing over the messages of lane `own` (they count as skipped, not delivered):
  /// a topic's bridge exports what the host's publishers send, never what it imported through
  /// its own lane. `own` out of range (a writer without a lane) passes over nothing.
  bool read_except(T& out, std::uint32_t own) noexcept {
    if (own < kMaxPublishers) pass_over(own);
    const std::uint32_t lanes = lane_count();
    std::uint32_t lane = next_lane_;
    for (std::uint32_t k = 0; k < lanes; ++k, ++lane) {
      if (lane >= lanes) lane = 0;
      if (lane != own && read_lane(lane, out)) {
        next_lane_ = lane + 1;
        return true;
      }
    }
    return false;
  }

  /// True if read() would return a message.
  bool has_message() const noexcept {
    const std::uint32_t lanes = lane_count();
    for (std::uint32_t l = 0; l < lanes; ++l)
      if (slot_has(slot_of(l, cursor_[l]), cursor_[l])) return true;
    return false;
  }

  /// Unread messages still in the ring.
  std::uint64_t pending() const noexcept {
    const std::uint32_t lanes = lane_count();
    std::uint64_t n = 0;
    for (std::uint32_t l = 0; l < lanes; ++l) {
      const std::uint64_t head = ring_.lane(l).head.load(std::memory_order_acquire);
      if (head > cursor_[l]) n += std::min<std::uint64_t>(head - cursor_[l], ring_.capacity());
    }
    return n;
  }

  /// Corrupt slots read() skipped (serialized messages only; see ReadStatus::Corrupt).
  std::uint64_t corrupt() const noexcept { return corrupt_before_ + corrupt_; }

  /// Messages this subscriber lost to overwrites, including ones not yet noticed by read().
  std::uint64_t lost() const noexcept {
    // The shared cursors mirror cursor_ (published on every advance).
    return lost_before_ + lost_ + (subscribed() ? ring_.unnoticed_losses(entry_) : 0);
  }

  /// Copies the newest message of the topic. When subscribed, everything published before it
  /// counts as read (skipped; losses among them still count as lost), so read() then returns
  /// only newer messages.
  bool read_latest(T& out) noexcept {
    std::uint64_t heads[kMaxPublishers];
    for (int attempt = 0; attempt < 64; ++attempt) {
      // Snapshot every head first: messages sent after this point are never skipped.
      const std::uint32_t lanes = lane_count();
      for (std::uint32_t l = 0; l < lanes; ++l) heads[l] = ring_.lane(l).head.load(std::memory_order_acquire);
      std::uint32_t lane = ring_.header().latest_lane(std::memory_order_acquire);
      if (lane >= lanes || heads[lane] == 0) {
        // The hint is not visible yet: take any lane that has data.
        lane = lanes;
        for (std::uint32_t l = 0; l < lanes; ++l)
          if (heads[l] != 0) lane = l;
        if (lane == lanes) return false;
      }
      // Never go back behind a message this handle already received.
      const std::uint64_t pos = subscribed() ? std::max(heads[lane], cursor_[lane]) : heads[lane];
      const ReadStatus st = read_slot(slot_of(lane, pos - 1), pos - 1, out);
      if (st == ReadStatus::Corrupt) return false;  // the newest message is unreadable (read() counts it)
      if (st != ReadStatus::Ok) {
        cpu_relax();
        continue;
      }
      if (subscribed()) {
        heads[lane] = pos;
        skip_to(heads, lanes);
      }
      return true;
    }
    return false;
  }

 private:
  static constexpr std::uint32_t kNone = ~0u;

  const std::byte* slot_of(std::uint32_t lane, std::uint64_t seq) const noexcept {
    if constexpr (kBytes) return slots_ + lane * lane_bytes_ + (seq & mask_) * stride_;
    else return slots_ + lane * lane_bytes_ + (seq & mask_) * slot_stride_for(sizeof(T));
  }

  [[gnu::always_inline]] bool read_lane(std::uint32_t lane, T& out) noexcept {
    // Lost and corrupt slots are passed over, but at most two rings' worth per call: a live
    // writer never leaves more, and a segment whose head and slots contradict each other (a
    // corrupt or hostile segment, found by fuzz_shm) must not keep a reader here for 2^64 steps.
    for (std::uint64_t steps = 0; steps <= 2 * (mask_ + 1); ++steps) {
      const std::uint64_t c = cursor_[lane];
      switch (read_slot(slot_of(lane, c), c, out)) {
        case ReadStatus::Ok:
          cursor_[lane] = c + 1;
          // Relaxed, and only now that the copy is validated: the cursor publishes no data,
          // and a writer that sees it late only waits longer (ring_control.hpp says why).
          shared_cursor_[lane].store(c + 1, std::memory_order_relaxed);
          return true;
        case ReadStatus::Empty:
          return false;
        case ReadStatus::Lost:
          skip_lost(lane);
          break;
        case ReadStatus::Corrupt:
          ++corrupt_;
          cursor_[lane] = c + 1;
          shared_cursor_[lane].store(c + 1, std::memory_order_relaxed);
          break;
      }
    }
    return false;  // the next read goes on from here
  }

  void take_entry(std::uint32_t entry) noexcept {
    entry_ = entry;
    shared_cursor_ = ring_.subscriber(entry_).cursor;
    // Acquire: an adopted entry's cursors were stored by another process.
    for (std::uint32_t l = 0; l < kMaxPublishers; ++l)
      start_[l] = cursor_[l] = shared_cursor_[l].load(std::memory_order_acquire);
    lost_before_ += lost_;
    corrupt_before_ += corrupt_;
    skipped_ = lost_ = corrupt_ = 0;
  }

  // Moves past messages not read (skipped or lost): nothing was copied, so the relaxed
  // store orders nothing the writer could overwrite too early.
  void advance(std::uint32_t lane, std::uint64_t to) noexcept {
    cursor_[lane] = to;
    shared_cursor_[lane].store(to, std::memory_order_relaxed);
  }

  // Moves lane `lane`'s cursor to its head, counting what it passes as skipped.
  void pass_over(std::uint32_t lane) noexcept {
    const std::uint64_t head = ring_.lane(lane).head.load(std::memory_order_acquire);
    if (cursor_[lane] >= head) return;
    skipped_ += head - cursor_[lane];
    advance(lane, head);
  }

  // Marks everything before heads[] as read: messages still in the ring are skipped, those
  // already overwritten are lost (so dropped counts never go down).
  [[gnu::noinline]] void skip_to(const std::uint64_t* heads, std::uint32_t lanes) noexcept {
    const std::uint64_t cap = ring_.capacity();
    for (std::uint32_t l = 0; l < lanes; ++l) {
      const std::uint64_t to = heads[l];
      if (cursor_[l] >= to) continue;
      const std::uint64_t oldest = to > cap ? to - cap : 0;
      const std::uint64_t gone = oldest > cursor_[l] ? oldest - cursor_[l] : 0;
      skipped_ += to - cursor_[l] - gone;
      lost_ += gone;
      advance(l, to);
      if (gone != 0) ring_.header().dropped_total.fetch_add(gone, std::memory_order_relaxed);
    }
  }

  // Slow path: message cursor_[lane] was overwritten; move to the oldest one still there.
  [[gnu::noinline]] void skip_lost(std::uint32_t lane) noexcept {
    const std::uint64_t c = cursor_[lane];
    const std::uint64_t head = ring_.lane(lane).head.load(std::memory_order_acquire);
    const std::uint64_t cap = ring_.capacity();
    // The oldest message that can still be there is head - cap (unless a write of `head` is
    // under way; then reading it fails again and we come back here one step further).
    const std::uint64_t oldest = head > cap ? head - cap : 0;
    const std::uint64_t next = std::max(c + 1, oldest);
    lost_ += next - c;
    advance(lane, next);  // first, so the topic-wide sum never counts these twice
    ring_.header().dropped_total.fetch_add(next - c, std::memory_order_relaxed);
  }

  // Hot fields first, read on every receive.
  const std::byte* slots_ = nullptr;  // lane 0's first slot
  std::uint64_t mask_ = 0;
  std::size_t lane_bytes_ = 0;
  std::size_t stride_ = 0;  // used for ByteMessage only (fixed-size T: a constant)
  // Lanes that may hold data: the shared high-water mark, never above kMaxPublishers whatever
  // another process wrote there.
  std::uint32_t lane_count() const noexcept {
    return std::min(lane_hwm_->load(std::memory_order_acquire), kMaxPublishers);
  }
  const std::atomic<std::uint32_t>* lane_hwm_ = nullptr;
  std::atomic<std::uint64_t>* shared_cursor_ = nullptr;  // our entry's cursors; null when not subscribed
  std::uint32_t next_lane_ = 0;
  std::uint64_t cursor_[kMaxPublishers]{};
  Ring ring_;
  std::uint64_t token_ = 0;
  std::uint32_t entry_ = kNone;
  std::uint64_t lost_ = 0;              // overwritten before we read them (this subscription)
  std::uint64_t lost_before_ = 0;       // the same, for earlier subscriptions of this handle
  std::uint64_t skipped_ = 0;           // passed over by read_latest (this subscription)
  std::uint64_t delivered_before_ = 0;  // returned by read() in earlier subscriptions
  std::uint64_t corrupt_ = 0;           // skipped by read() as corrupt (this subscription)
  std::uint64_t corrupt_before_ = 0;    // the same, for earlier subscriptions
  std::uint64_t start_[kMaxPublishers]{};
};

}  // namespace horus::shm

HORUS_API_END
