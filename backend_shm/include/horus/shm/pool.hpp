// The large-data pool: where the bytes of images, point clouds, depth images and tensors live,
// so that a topic's ring carries only their fixed-size descriptor (zero-copy).
//
// The pool sits in the same region as the ring (heap memory for a process-local topic, the
// topic's shared-memory segment otherwise), with offsets only:
//
//   offset 0        PoolHeader    constants, and counters of reused and exhausted slots
//   slots_offset    PoolSlot[lanes * slots_per_lane]   generation, last use, pins per participant
//   data_offset     lane 0: slot data[slots_per_lane] | lane 1: ...   (each slot_bytes, page-aligned)
//
// Every publisher lane of the ring has its own slots, written only by the lane's owner, so a
// publisher never contends with another for a slot. A slot's generation is even when its bytes
// are stable (published, or never used) and odd while its owner writes them (a loan). A
// descriptor on the ring names a slot and the even generation its bytes were published with.
//
// A subscriber that reads a descriptor pins the slot (pins[participant] += 1) and then checks
// that the generation is still the published one: if not, the slot was reused and the message
// counts as lost, exactly like a ring overwrite. A writer that wants a slot makes its
// generation odd and then checks that nobody pins it (else it puts the generation back and
// takes another slot). Both sides use sequentially consistent operations, so either the
// writer sees the pin or the subscriber sees the new generation: a pinned slot is never
// rewritten, and a subscriber never accepts bytes being rewritten.
//
// Pins are counted per participant (process), not per slot, so that when a process dies
// holding images, the segment's reaper clears its counts (release_participant) and the slots
// come back: a crashed holder never leaks a slot. A writer that dies while filling a slot
// leaves an odd generation that no descriptor names; the lane's next owner reuses the slot.
//
// The writer takes the free slot published longest ago. A lane has more slots than the ring
// has per lane (slots_per_lane > capacity), so a slot is reused only once the ring has
// overwritten every message naming it, unless subscribers keep more than the spare slots
// pinned; then the oldest unread messages are lost (and counted), and when every slot is
// pinned the send is refused (counted in PoolHeader::exhausted).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "horus/shm/ring.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

/// Processes that can attach to one topic at once (the participant table and the pins).
inline constexpr std::uint32_t kMaxParticipants = 64;
inline constexpr std::uint64_t kPoolMagic = 0x314C'4F50'5355'524FULL;  // "ORUSPOL1"
/// Most slots a lane may have.
inline constexpr std::uint32_t kMaxPoolSlotsPerLane = 64;
inline constexpr std::size_t kPoolPage = 4096;

struct PoolConfig {
  std::uint64_t slot_bytes = 0;      // largest message's bytes
  std::uint32_t slots_per_lane = 0;  // 2 to kMaxPoolSlotsPerLane
};

struct alignas(kCacheLine) PoolHeader {
  std::uint64_t magic;
  std::uint64_t slot_bytes;    // usable bytes per slot (as configured)
  std::uint64_t slot_stride;   // bytes between slots' data (slot_bytes rounded up to a page)
  std::uint32_t slots_per_lane;
  std::uint32_t lanes;
  std::uint64_t slots_offset;  // PoolSlot table, from the pool's base
  std::uint64_t data_offset;   // slot data, from the pool's base
  std::uint64_t total_size;
  // Participants 0 .. participants-1 may pin (a high-water mark): a writer checks only those.
  alignas(kCacheLine) std::atomic<std::uint32_t> participants;
  alignas(kCacheLine) std::atomic<std::uint64_t> reused;     // unread messages lost to a slot's reuse
  alignas(kCacheLine) std::atomic<std::uint64_t> exhausted;  // sends refused: every slot of the lane pinned
};

struct alignas(kCacheLine) PoolSlot {
  std::atomic<std::uint64_t> gen;    // even: stable; odd: being written
  std::atomic<std::uint64_t> stamp;  // lane sequence + 1 when last published (the oldest free slot is reused first)
  // The process writing the slot while gen is odd: its slot is taken over only once it is gone.
  std::atomic<std::uint64_t> claimer_start;  // start time of the claiming process
  std::atomic<std::uint32_t> claimer_pid;
  // The pins on lines of their own: subscribers write them, and a writer scanning its slots'
  // stamps must not miss the cache on every slot a subscriber pinned.
  alignas(kCacheLine) std::atomic<std::uint32_t> pins[kMaxParticipants];
};
static_assert(sizeof(PoolSlot) == 5 * kCacheLine, "a pool slot header is one line of state and four of pins");

class Pool {
 public:
  /// A slot being written by its lane's owner (its generation is `gen`, odd).
  struct Claim {
    std::uint32_t slot = 0;
    std::uint64_t gen = 0;
  };
  /// Who claims: a process (pid and start time, see process_start_time()).
  struct Claimer {
    std::uint32_t pid = 0;
    std::uint64_t start_time = 0;
  };

  Pool() = default;
  static std::size_t required_size(const PoolConfig& cfg) noexcept;
  /// An error text, or nothing.
  static std::optional<std::string> check_config(const PoolConfig& cfg);
  /// Initialises a zero-filled region of at least required_size(cfg) bytes.
  static Pool format(void* region, const PoolConfig& cfg) noexcept;
  /// Checks a formatted pool of `size` bytes; an error text on a bad header.
  static std::optional<std::string> validate(const void* region, std::size_t size);
  /// Attaches to a pool that validate() accepted (or format() made).
  static Pool attach(void* region) noexcept;

  explicit operator bool() const noexcept { return hdr_ != nullptr; }
  PoolHeader& header() const noexcept { return *hdr_; }
  // The geometry, copied at attach (after validate): what another process writes into the
  // shared header later cannot move a bound this process checks against.
  std::uint64_t slot_bytes() const noexcept { return slot_bytes_; }
  std::uint32_t slots_per_lane() const noexcept { return slots_per_lane_; }
  std::uint32_t slot_count() const noexcept { return slots_per_lane_ * lanes_; }
  PoolSlot& slot(std::uint32_t i) const noexcept { return slots_[i]; }
  std::uint8_t* data(std::uint32_t i) const noexcept { return data_ + static_cast<std::size_t>(i) * stride_; }
  /// Byte offset of slot i's data from the pool's base (what a descriptor records).
  std::uint64_t offset_of(std::uint32_t i) const noexcept { return data_offset_ + std::uint64_t{i} * stride_; }

  // -- writing: only the owner of `lane` ----------------------------------------
  /// Claims the free slot of `lane` published longest ago, among those whose stamp is at most
  /// `max_stamp` (slots every subscriber has read: what try_send needs). A slot being written
  /// (a loan) is free only when the process that claimed it is gone. nullopt when no slot is
  /// free; the caller counts the refusal (PoolHeader::exhausted).
  std::optional<Claim> claim(std::uint32_t lane, const Claimer& me,
                             std::uint64_t max_stamp = ~std::uint64_t{0}) const noexcept;
  /// Makes a claimed slot's bytes visible; returns the generation descriptors must carry.
  std::uint64_t publish(const Claim& c, std::uint64_t stamp) const noexcept;
  /// Gives a claimed slot back unpublished (reused first); false (nothing done) when it was
  /// published or given back already. Safe from any thread.
  bool abandon(const Claim& c) const noexcept;
  /// True while `c` is claimed and neither published nor given back.
  bool claimed(const Claim& c) const noexcept { return slots_[c.slot].gen.load(std::memory_order_acquire) == c.gen; }

  // -- reading -------------------------------------------------------------------
  /// Pins slot `i` for participant `p` if it still holds generation `gen`; false (nothing
  /// pinned) when the slot was reused or `i` is out of range.
  bool pin(std::uint32_t i, std::uint64_t gen, std::uint32_t p) const noexcept;
  void unpin(std::uint32_t i, std::uint32_t p) const noexcept;
  /// Participant `p` may pin from now on (call before its first pin()).
  void admit(std::uint32_t p) const noexcept;
  /// Drops every pin of participant `p` (a process that died, or left).
  void release_participant(std::uint32_t p) const noexcept;
  /// Slots pinned by anyone now (for tools and tests).
  std::uint32_t pinned_slots() const noexcept;

 private:
  bool pinned(const PoolSlot& s) const noexcept;
  PoolHeader* hdr_ = nullptr;
  PoolSlot* slots_ = nullptr;
  std::uint8_t* data_ = nullptr;
  std::uint64_t slot_bytes_ = 0, stride_ = 0, data_offset_ = 0;
  std::uint32_t slots_per_lane_ = 0, lanes_ = 0;
};

}  // namespace horus::shm

HORUS_API_END
