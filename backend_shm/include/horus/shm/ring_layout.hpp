// The ring region's layout: what its bytes are, nothing about who may touch them when.
//
// The memory is one flat region with a fixed layout and offsets only (no
// pointers), so the same code runs on heap memory (process-local topics) and on
// a POSIX shared-memory segment:
//
//   offset 0                    RingHeader            (constants, lane/sub high-water marks, drop total, doorbell)
//   lanes_offset                LaneHeader[kMaxPublishers]    (owner token, head)
//   subs_offset                 SubscriberEntry[kMaxSubscribers] (state, owner, cursor per lane)
//   slots_offset                lane 0: slot[capacity] | lane 1: slot[capacity] | ...
//
//   slot = [ seq : u64 ][ payload : payload_size rounded up to 8 ]   stride: power of two <= 64 B,
//                                                                   else a multiple of 64 B, so a
//                                                                   small slot never straddles lines
//
// The sequence protocol of a slot is in seqlock_slot.hpp; who claims lanes and subscriber
// entries, and how the heads and cursors below are ordered, is in ring_control.hpp.
#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "horus/shm/doorbell.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

inline constexpr std::size_t kCacheLine = 64;
/// Publishers (sending handles) a topic can have at once.
inline constexpr std::uint32_t kMaxPublishers = 32;
/// Subscribers (receiving handles) a topic can have at once.
inline constexpr std::uint32_t kMaxSubscribers = 64;
/// Largest number of slots per lane.
inline constexpr std::uint32_t kMaxCapacity = 1u << 20;
inline constexpr std::uint64_t kRingMagic = 0x3147'4E52'5355'524FULL;  // "ORUSRNG1"
inline constexpr std::uint32_t kLayoutVersion = 5;  // 2: the doorbell; 3: the latest lane in its state word; 4: two classes
                                                    // of waiters; 5: the bridge class forwarded to a network engine

struct alignas(2 * kCacheLine) RingHeader {  // its doorbell has a 128-byte pair of its own
  // Written once by format(), read-only afterwards.
  std::uint64_t magic;
  std::uint32_t layout_version;
  std::uint32_t capacity;       // slots per lane, a power of two
  std::uint32_t payload_size;   // bytes of one message
  std::uint32_t slot_stride;    // bytes between slots
  std::uint64_t type_hash;      // layout hash of the message type
  std::uint64_t lanes_offset;
  std::uint64_t subs_offset;
  std::uint64_t slots_offset;
  std::uint64_t total_size;
  // Read by every receive; changes only when a new lane or subscriber slot is first used.
  alignas(kCacheLine) std::atomic<std::uint32_t> lane_hwm;  // lanes [0, lane_hwm) may hold data
  std::atomic<std::uint32_t> sub_hwm;                       // entries [0, sub_hwm) may be active
  // Written by subscribers when they detect a loss (slow path only).
  alignas(kCacheLine) std::atomic<std::uint64_t> dropped_total;
  // Blocked receivers (doorbell.hpp), and in the low half of doorbell.state the lane that sent
  // last (for read_latest; latest_lane()). Read by every send; written only when the sending
  // lane changes and as receivers go to sleep and wake up, so a topic with one publisher and
  // polling receivers keeps it in every core's cache. A 128-byte pair of its own.
  alignas(2 * kCacheLine) Doorbell doorbell;

  std::uint32_t latest_lane(std::memory_order order) const noexcept {
    return static_cast<std::uint32_t>(doorbell.state.load(order));
  }
};

struct alignas(kCacheLine) LaneHeader {
  std::atomic<std::uint64_t> owner;                     // 0: free, else the publisher's token
  alignas(kCacheLine) std::atomic<std::uint64_t> head;  // next sequence number to write
};

struct alignas(kCacheLine) SubscriberEntry {
  static constexpr std::uint32_t kFree = 0, kClaiming = 1, kActive = 2;
  std::atomic<std::uint32_t> state;
  std::atomic<std::uint64_t> owner;
  // This entry's share of the doorbell's waiters (taken back when a dead owner is reaped).
  WaitShare waiting;
  // Next sequence the subscriber will read, per lane (published after each read).
  alignas(kCacheLine) std::atomic<std::uint64_t> cursor[kMaxPublishers];
};

static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "the ring needs lock-free 64-bit atomics");
static_assert(std::atomic<std::uint32_t>::is_always_lock_free, "the ring needs lock-free 32-bit atomics");
static_assert(std::is_standard_layout_v<RingHeader> && std::is_standard_layout_v<LaneHeader> &&
                  std::is_standard_layout_v<SubscriberEntry>,
              "ring structures live in shared memory and must have a fixed layout");

/// Bytes between consecutive slots for a payload of the given size.
constexpr std::uint32_t slot_stride_for(std::uint32_t payload_size) noexcept {
  const std::uint32_t raw = 8 + ((payload_size + 7u) & ~7u);
  if (raw <= kCacheLine) return std::bit_ceil(raw);
  return static_cast<std::uint32_t>((raw + kCacheLine - 1) / kCacheLine * kCacheLine);
}

/// Default slots per lane: 16 to 1024, more for small messages (about 64 KiB per lane).
constexpr std::uint32_t default_capacity(std::uint32_t payload_size) noexcept {
  const std::uint32_t by_size = std::bit_floor(std::max<std::uint32_t>(1u, (64u * 1024u) / slot_stride_for(payload_size)));
  return std::clamp<std::uint32_t>(by_size, 16u, 1024u);
}

struct RingConfig {
  std::uint32_t capacity = 0;      // slots per lane (power of two)
  std::uint32_t payload_size = 0;  // bytes per message
  std::uint64_t type_hash = 0;
  bool process_private = false;  // a heap region (one process): private futex wake-ups
};

}  // namespace horus::shm

HORUS_API_END
