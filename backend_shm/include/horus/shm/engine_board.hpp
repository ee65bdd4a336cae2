// EngineBoard: how a publisher of any process wakes the one network engine of the process that
// bridges its fleet topic, whatever number of topics that engine serves.
//
// A fleet topic's export used to sleep on its ring's doorbell, one thread per topic and process
// (futex_waitv takes at most 128 words). The engine of a process (fleet/) instead sleeps on one
// futex word of its own, in a host-wide board:
//
//   /dev/shm/horus.<namespace>@engines.v1      a header, then kEngineSlots slots of 640 bytes;
//                                              zero = empty
//
//   EngineBoardHeader  released  bridge claims given up by a live holder (a topic closed), host-
//                          wide: the watchers' control threads look at it (one load every 50 ms)
//                          and look at their topics' claims only when it moved.
//                      link_tat  the host's link budget (network.max_bandwidth), shared by every
//                          bridge of the host: when the link would have sent everything admitted
//                          so far (CLOCK_MONOTONIC ns; a GCRA "theoretical arrival time"). A
//                          message of b bytes is admitted when link_tat - now <= its priority's
//                          tolerance and moves link_tat to max(link_tat, now) + b / rate.
//                          Added in the header's padding: boards of older processes ignore it.
//   EngineSlot   owner     (pid << 32) | generation; 0: free. The engine claims a slot (under
//                          flock on the file) and frees it when it stops; a dead owner's slot is
//                          claimed again (its pid no longer runs).
//                word      the futex word: +1 per notification; the engine sleeps on it.
//                summary   bit g: pending[g] may hold bits.
//                pending   one bit per topic the engine holds (topic index mod kEngineBits).
//
// A held topic's doorbell carries `forward` (doorbell.hpp): slot, bit and generation. When a
// publisher rings the doorbell and finds the bridge class armed, it clears the armed bit (one
// publisher does: compare-exchange), sets the topic's bit, bumps `word` and makes one
// FUTEX_WAKE on it. The engine takes the bits, re-arms those topics, exports what they hold,
// and sleeps on `word` with the value it read before it looked (an eventcount: a notification
// in between makes FUTEX_WAIT return at once). Nothing here is on the send path of a topic whose
// bridge is not armed: a draining engine costs its publishers nothing.
//
// Lifetime. The file is created zero-filled (all slots free) by the first engine of the
// namespace and unlinked by the last one that frees its slot (both under flock). A publisher maps
// the board once per process, at its first forwarded ring; a ring whose generation does not
// match its slot (the board was unlinked and made anew, or the engine is gone) maps the current
// board once more and tries again; a mapping is never unmapped (another thread may use it).
#pragma once

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <expected>
#include <string>

#include "horus/shm/shm_segment.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

inline constexpr std::uint32_t kEngineSlots = 128;       // engines (processes x transports) per host
inline constexpr std::uint32_t kEngineGroups = 64;       // 64-bit words of pending bits per engine
inline constexpr std::uint32_t kEngineBits = 64 * kEngineGroups;  // topics per engine before bits are shared

struct alignas(2 * kCacheLine) EngineBoardHeader {
  std::atomic<std::uint64_t> released;  // bridge claims given up (ShmSegment::release_bridge)
  alignas(kCacheLine) std::atomic<std::int64_t> link_tat;  // the host's link budget (see above)
};
static_assert(sizeof(EngineBoardHeader) == 2 * kCacheLine, "the board's slots stay where they were");

/// The host link budget's admission (GCRA) on `tat`: true, and `tat` moved by `cost_ns`, when
/// the link's backlog (tat - now) is at most `tolerance_ns`.
inline bool admit_on_link(std::atomic<std::int64_t>& tat, std::int64_t now_ns, std::int64_t cost_ns,
                          std::int64_t tolerance_ns) noexcept {
  std::int64_t cur = tat.load(std::memory_order_relaxed);
  for (;;) {
    const std::int64_t start = cur > now_ns ? cur : now_ns;
    if (start - now_ns > tolerance_ns) return false;
    if (tat.compare_exchange_weak(cur, start + cost_ns, std::memory_order_relaxed)) return true;
  }
}

struct alignas(2 * kCacheLine) EngineSlot {
  std::atomic<std::uint64_t> owner;    // (pid << 32) | generation; 0: free
  std::atomic<std::uint32_t> word;     // the futex word the engine sleeps on
  std::atomic<std::uint32_t> generation;  // claims of this slot so far (the owner's low half)
  std::atomic<std::uint64_t> summary;  // bit g: pending[g] may hold bits
  alignas(kCacheLine) std::atomic<std::uint64_t> pending[kEngineGroups];
};
static_assert(std::is_standard_layout_v<EngineSlot>, "engine slots live in shared memory");

/// What a doorbell's `forward` word holds: (slot + 1) << 48 | bit << 32 | generation.
constexpr std::uint64_t engine_forward(std::uint32_t slot, std::uint32_t bit, std::uint32_t generation) noexcept {
  return (std::uint64_t{slot + 1} << 48) | (std::uint64_t{bit & (kEngineBits - 1)} << 32) | generation;
}

/// The publisher's side: sets the topic's bit in the engine named by `forward` and wakes it.
/// False when no live engine has that slot and generation (nothing was done).
bool notify_engine(std::uint64_t forward) noexcept;

/// A holder gave a bridge claim up: counts it on the board (when this process maps one: it had
/// an engine, or rang one).
void note_bridge_released() noexcept;
/// Claims given up on this host so far (0 without a board mapped).
std::uint64_t bridge_releases() noexcept;

/// This process's slot on the host's board: one per network engine. Move-only; frees the slot.
class EngineBell {
 public:
  /// Claims a free slot of the board of namespace `ns` (creating the board with `mode`).
  static std::expected<EngineBell, SegmentError> claim(const std::string& ns, mode_t mode);

  EngineBell() = default;
  EngineBell(EngineBell&& o) noexcept { *this = std::move(o); }
  EngineBell& operator=(EngineBell&& o) noexcept;
  EngineBell(const EngineBell&) = delete;
  EngineBell& operator=(const EngineBell&) = delete;
  ~EngineBell();

  explicit operator bool() const noexcept { return slot_ != nullptr; }
  /// The value a doorbell's `forward` holds for the topic with this bit.
  std::uint64_t forward(std::uint32_t bit) const noexcept { return engine_forward(index_, bit, generation_); }
  /// The futex word's value: read it before looking for work, sleep with it (wait()).
  std::uint32_t word() const noexcept { return slot_->word.load(std::memory_order_acquire); }
  /// Sets a bit and wakes the engine from this process (work found by another thread).
  void notify(std::uint32_t bit) noexcept;
  /// Wakes the engine without a bit (a command for it).
  void poke() noexcept;
  /// Takes the pending bits: calls fn(bit) for each set one.
  template <class F>
  void take(F&& fn) {
    std::uint64_t groups = slot_->summary.exchange(0, std::memory_order_acq_rel);
    while (groups != 0) {
      const int g = __builtin_ctzll(groups);
      groups &= groups - 1;
      std::uint64_t bits = slot_->pending[g].exchange(0, std::memory_order_acq_rel);
      while (bits != 0) {
        const int b = __builtin_ctzll(bits);
        bits &= bits - 1;
        fn(static_cast<std::uint32_t>(g * 64 + b));
      }
    }
  }
  /// The host's link budget: admits `bytes` at `ns_per_byte` when the link's backlog is within
  /// `tolerance_ns` (admit_on_link on the board's header).
  bool admit_link(std::size_t bytes, double ns_per_byte, std::int64_t tolerance_ns) noexcept;
  /// Sleeps while the word holds `seen`, until `deadline` (time_point::max(): none).
  void wait(std::uint32_t seen, std::chrono::steady_clock::time_point deadline) noexcept;

 private:
  void release() noexcept;
  int fd_ = -1;
  void* base_ = nullptr;
  EngineSlot* slot_ = nullptr;
  std::uint32_t index_ = 0;
  std::uint32_t generation_ = 0;
  std::string name_;
};

/// The board's shm name for namespace `ns` ("/horus.<ns>@engines.v1": no topic name has '@').
std::string engine_board_name(const std::string& ns);

}  // namespace horus::shm

HORUS_API_END
