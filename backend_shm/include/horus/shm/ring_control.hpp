// Ring: the view of a formatted ring region, and its control plane (the slow paths).
//
// Formatting and validating a region (src/ring_layout.cpp) and everything that is not a send
// or a receive (src/ring_control.cpp): claiming and releasing lanes and subscriber entries,
// and the counts. The hot paths are RingWriter (ring_writer.hpp) and RingReader
// (ring_reader.hpp); the bytes are described in ring_layout.hpp.
//
// Owner tokens. Every lane and subscriber entry is claimed with a token: a non-zero 64-bit
// value that the ring only compares (0 means free). Topic makes them (pid << 32) | counter,
// so a shared segment can tell whose lane or entry it is after the owner died and release it
// in its place (ShmSegment's reaper, with token_pid() in shm_segment.hpp); that is the only
// place that gives a token a meaning. Releasing takes the token and does nothing when the
// lane or entry has another owner by then, so a late release never frees someone else's.
//
// Lanes. owner goes 0 -> token (compare-exchange, so exactly one claimer wins) and back to 0
// on release. The head survives a release: the lane's next owner continues its sequence, so
// subscribers' cursors for that lane stay valid. lane_hwm only grows.
//
// Subscriber entries. state goes kFree -> kClaiming (compare-exchange: the claimer has the
// entry to itself) -> kActive once owner and a cursor per lane (each lane's head of that
// moment: only later messages are delivered) are stored; back to kFree on remove, after its
// unnoticed losses are added to dropped_total. Writers wait only for kActive entries.
// sub_hwm only grows.
//
// Memory order of the shared counters (heads, cursors, hints): which store orders what.
// - Slot sequence words carry the messages; their protocol is in seqlock_slot.hpp. Nothing
//   below publishes payload: every payload read is validated by its slot's sequence, so a
//   stale head or cursor can make a reader or writer retry or wait, never see a torn message.
// - LaneHeader::head. Written only by the lane's owner (RingWriter::commit), with a release
//   store after the slot's committing store; every other thread loads it with acquire. So a
//   thread that sees head == s + 1 also sees message s committed (or overwritten) in its slot:
//   read_latest() reads pos - 1 at once, skip_lost() resumes at head - capacity, pending()
//   counts only committed messages. The writer keeps its own copy (head_) and reads the shared
//   head only when it claims the lane: the claim's compare-exchange (acq_rel) reads the
//   owner word written by the previous owner's release, so that owner's last head store
//   happens before this load. (A reaped owner is dead: its last head may be one behind an odd
//   slot it never finished, and the next owner writes that sequence number again.)
// - SubscriberEntry::cursor[l]. Written only by the entry's owner (RingReader, and
//   add_subscriber() while the entry is kClaiming) with relaxed stores. That is enough:
//   * a cursor publishes no data. Writers read it (space_limit(), acquire loads) only to know
//     how far the subscriber got. Cursors only grow, so a stale value is a smaller one: the
//     writer believes it has less room than it has and waits or tries again (conservative).
//   * RingReader stores c + 1 only after read_slot() returned Ok, i.e. after the copy and its
//     sequence re-check. The copy cannot see a write that follows a writer's load of c + 1:
//     the copy's word loads are acquire and the writer's word stores release, so that would
//     order the writer's load before the very store it read (impossible); in the memcpy path
//     the acquire fence after the copy keeps its loads before the cursor store. And had it
//     seen one, the re-check would have returned Lost anyway.
//   * a new entry's cursors and owner are stored before state = kActive (release); writers
//     and counters load state with acquire before they read cursors, so they never see an
//     active entry with the cursors of its previous user.
//   * the owner reads its own cursors (subscribe(), lost()): its own stores, program order.
//   * the counts (unnoticed_losses(), undetected_losses()) are statistics: another thread
//     may see a cursor a moment late, and a loss may then show up both there and in
//     dropped_total (also relaxed) for that moment.
// - RingHeader::latest_lane() (the low half of doorbell.state). Relaxed: a hint. read_latest() checks it against the heads it
//   loaded (acquire) and reads the message through its slot's sequence, so a stale hint only
//   chooses another lane's newest message.
// - RingHeader::doorbell and SubscriberEntry::waiting: doorbell.hpp (a publisher's relaxed
//   load of the waiter count after its head store, and the bounded race that leaves).
// - RingHeader::dropped_total: relaxed read-modify-writes, a statistic no decision reads.
// - lane_hwm / sub_hwm: raised with an acq_rel compare-exchange once the lane or entry is
//   claimed, loaded with acquire. They only bound loops: a reader that loads a value from
//   before a raise skips the new lane this time and reads its messages on a later call (its
//   cursor for that lane does not move); a writer that does not see a new entry yet does
//   not wait for it, as if it had not joined yet.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "horus/shm/ring_layout.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

/// A non-owning view of a formatted ring region. Copyable; all state lives in the region.
class Ring {
 public:
  Ring() = default;

  // --- The region (src/ring_layout.cpp) ---

  /// Bytes a region needs for this configuration.
  static std::size_t required_size(const RingConfig& cfg) noexcept;
  /// Checks a configuration; returns an error text or nothing.
  static std::optional<std::string> check_config(const RingConfig& cfg);
  /// Initialises a zero-filled region of at least required_size(cfg) bytes.
  static Ring format(void* region, const RingConfig& cfg) noexcept;
  /// Attaches to a region formatted by format(); returns an error text on a bad header.
  static std::optional<std::string> validate(const void* region, std::size_t size);
  static Ring attach(void* region) noexcept;

  RingHeader& header() const noexcept { return *hdr_; }
  LaneHeader& lane(std::uint32_t i) const noexcept { return lanes_[i]; }
  SubscriberEntry& subscriber(std::uint32_t i) const noexcept { return subs_[i]; }
  std::byte* lane_slots(std::uint32_t lane) const noexcept {
    return slots_ + static_cast<std::size_t>(lane) * capacity_ * stride_;
  }
  // The geometry, copied at attach (after validate): what another process writes into the
  // shared header later cannot move a bound this process checks against.
  std::uint32_t capacity() const noexcept { return capacity_; }
  std::uint32_t stride() const noexcept { return stride_; }
  std::uint32_t payload_size() const noexcept { return payload_size_; }
  explicit operator bool() const noexcept { return hdr_ != nullptr; }

  // --- The control plane (src/ring_control.cpp) ---

  /// Claims a free lane for a publisher; returns its index, or nothing when all are taken.
  std::optional<std::uint32_t> claim_lane(std::uint64_t token) const noexcept;
  void release_lane(std::uint32_t lane, std::uint64_t token) const noexcept;
  /// Claims a subscriber entry whose cursors start at the lanes' current heads, and rings the
  /// doorbell (a paused fleet bridge resumes receiving when it sees a subscriber).
  std::optional<std::uint32_t> add_subscriber(std::uint64_t token) const noexcept;
  void remove_subscriber(std::uint32_t entry, std::uint64_t token) const noexcept;
  /// Hands lane `lane` / active subscriber entry `entry` from owner `from` to `to` (a fleet
  /// topic's bridge taken over: ShmSegment::inherit_bridge). False when `from` no longer owns it.
  /// The entry keeps its cursors; waiters `from` left registered leave the doorbell's count.
  bool adopt_lane(std::uint32_t lane, std::uint64_t from, std::uint64_t to) const noexcept;
  bool adopt_subscriber(std::uint32_t entry, std::uint64_t from, std::uint64_t to) const noexcept;

  std::uint32_t publisher_count() const noexcept;
  std::uint32_t subscriber_count() const noexcept;
  /// The lowest head at which writing into `lane` would overwrite a message an active
  /// subscriber has not read: the slowest cursor + capacity, at most head + capacity. The
  /// subscriber entry owned by `self` (the writer's own handle) is not waited for.
  std::uint64_t space_limit(std::uint32_t lane, std::uint64_t head, std::uint64_t self) const noexcept;
  /// Messages subscriber `entry` lagged beyond capacity (overwritten) and has not yet noticed.
  std::uint64_t unnoticed_losses(std::uint32_t entry) const noexcept;
  /// The same, summed over all active subscribers.
  std::uint64_t undetected_losses() const noexcept;
  /// Messages sent on the topic since it was created (all lanes).
  std::uint64_t total_sent() const noexcept;

  // --- Event-driven receive (doorbell.hpp) ---

  Doorbell& doorbell() const noexcept { return hdr_->doorbell; }
  /// A send found waiters: wakes them if they may be asleep (RingWriter's slow path); false
  /// when nobody was armed.
  bool wake_waiters(std::uint32_t classes = Doorbell::kArmedAll) const noexcept;
  /// Takes back the doorbell registrations of waiters whose process is gone; returns how many.
  std::uint32_t reap_dead_waiters() const noexcept;
  /// True when subscriber `entry`, still owned by `token`, has a message it has not read (a
  /// lane head past its published cursor); false once the entry has another owner.
  bool has_unread(std::uint32_t entry, std::uint64_t token) const noexcept;
  /// The same, lane `skip` left out (a bridge's export: not what its own import wrote).
  bool has_unread_except(std::uint32_t entry, std::uint64_t token, std::uint32_t skip) const noexcept;

 private:
  explicit Ring(std::byte* base) noexcept;
  RingHeader* hdr_ = nullptr;
  LaneHeader* lanes_ = nullptr;
  SubscriberEntry* subs_ = nullptr;
  std::byte* slots_ = nullptr;
  std::uint32_t capacity_ = 0;
  std::uint32_t stride_ = 0;
  std::uint32_t payload_size_ = 0;
};

}  // namespace horus::shm

HORUS_API_END
