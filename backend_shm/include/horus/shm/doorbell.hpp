// Doorbell: how a blocked receiver is woken, through the memory its topic lives in.
//
// Every ring has one Doorbell in its header (a shared segment's or a heap region's), and a
// horus::Trigger has one in process memory. Two words:
//   state    its high half counts the threads that are about to sleep or asleep on it (the
//            waiters); its low half is the owner's: a ring keeps its latest-lane hint there
//            (ring_layout.hpp), so a publisher checks both with the one relaxed load it makes
//            after every send. No waiter and no lane change, the common case, costs that load.
//   word     the futex word. Its low bits are "armed": a waiter sets its bit just before it
//            sleeps, and the first publisher that finds it set clears it (compare-exchange, the
//            epoch in the bits above goes up) and makes the one FUTEX_WAKE. Later publishers
//            find it clear and make no syscall until a waiter has looked at the ring again and
//            re-armed it, so a waiter that is busy draining messages costs its publishers nothing.
//            Two classes of waiters, one bit each: handles (kArmedReader) and the network engine
//            that bridges a fleet topic (kArmedBridge). The bridge's import, writing what came
//            from the network, rings the handles only (it would wake the engine for a message
//            the bridge skips: its own); every other publisher rings both. The bridge class is a process's network engine
//            (fleet/), which holds many topics and sleeps on a word of its own: `forward` names it
//            (engine_board.hpp), and the publisher that clears kArmedBridge wakes it there.
//
// The waiting side (wait_any): register in the waiters, arm each word, look at the ring(s)
// again, then sleep in FUTEX_WAIT (one doorbell) or futex_waitv (several), with an absolute
// CLOCK_MONOTONIC deadline. Every return (woken, the word changed under us, a signal, a
// timeout, a spurious wake-up) goes back to looking at the rings; only a ready item or the
// deadline ends the wait.
//
// The one race, and how it is bounded. A publisher does not fence between its store of the
// lane head and its load of `waiters` (that fence would cost more than the whole send), so a
// publisher that loaded `waiters` just before a waiter registered may skip the wake while its
// head store is still on its way to memory, after the waiter has looked. Such a store becomes
// visible within nanoseconds (a store buffer drains by itself, and on any interrupt or context
// switch), so the waiter's first sleep after registering is capped at kFirstSlice: the message
// is then seen at most that late, never lost, whatever the timeout. Any later publisher sees
// the registration (it is a read-modify-write) and rings. A publisher that found waiters does
// fence before it looks at the armed bit (ring_doorbell): a waiter re-arms after every wake-up,
// and without that fence a message sent while it re-armed went unseen until the next send (a
// 6 MB image topic over Cyclone DDS delivered 15 messages/s to a blocked receiver, 350 with it).
// (Why not shorter: a futex sleep
// whose timeout is a few hundred microseconds away is woken twice as slowly on our VMs,
// 23 us instead of 11.6 us one-way in a raw futex ping-pong; from 5 ms on it costs nothing.)
//
// Processes that die. A waiter killed while blocked leaves its registration in the count; the
// count is kept per subscriber entry too (a WaitShare: how many, and the waiting pid), and it is
// taken back (a) by the segment's reaper when it frees a dead subscriber's entry
// (Ring::remove_subscriber), and (b) by a publisher that keeps finding waiters registered but
// nobody armed: every kStaleCheck such sends it looks for shares of processes that are gone
// (Ring::reap_dead_waiters). The kernel forgets a dead process's futex waits by itself. A publisher killed between clearing
// the armed bit and its FUTEX_WAKE leaves the waiter asleep until its first slice or its
// deadline, never longer.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <span>

#include "horus/detail/process.hpp"
#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

struct Doorbell {
  /// One waiter in `state` (the high half).
  static constexpr std::uint64_t kWaiter = std::uint64_t{1} << 32;
  /// The armed bits of `word`, by class of waiter, and its epoch's unit.
  static constexpr std::uint32_t kArmedReader = 1, kArmedBridge = 2, kArmedAll = 3, kEpoch = 4;
  std::atomic<std::uint64_t> state{0};  // high half: waiters; low half: the owner's (see above)
  std::atomic<std::uint32_t> word{0};   // the futex word; low bits: armed (kArmed*)
  std::uint32_t process_private = 0;    // 1: memory of one process only (FUTEX_PRIVATE_FLAG)
  // Where the bridge class sleeps when it is not on `word`: a network engine's slot on the
  // host's board (engine_board.hpp: engine_forward()); 0: on `word`, as readers do.
  std::atomic<std::uint64_t> forward{0};

  std::uint32_t waiters() const noexcept {
    return static_cast<std::uint32_t>(state.load(std::memory_order_relaxed) >> 32);
  }
};
static_assert(std::atomic<std::uint32_t>::is_always_lock_free);

/// One subscriber entry's part of a doorbell's waiter count (it lives in the entry).
struct WaitShare {
  std::atomic<std::uint32_t> count{0};
  std::atomic<std::int32_t> pid{0};  // the process that registered last
};

/// A fleet topic whose bridge this process holds: its publishers hand each message to the
/// network themselves (fleet/: inline export) instead of waking the engine. Process memory; a
/// RingWriter with one set wakes only the reader class after each send while `active` (the
/// engine stays asleep), then calls `run`. `active` implies the engine is registered as a
/// waiter, so every send reaches RingWriter::wake().
/// A forked child's copy is never active: `generation` is fork_generation() of the process that
/// activated it (the child's sends ring the bridge class instead, which reaches the parent).
struct InlineExport {
  std::atomic<bool> active{false};
  void (*run)(void* ctx) noexcept = nullptr;
  void* ctx = nullptr;
  std::uint32_t generation = 0;
};

/// How many fork()s lie between the first process and this one (the process context counts them,
/// horus/detail/process.hpp): one relaxed load tells a forked child's copy of process state from
/// the parent's.
using horus::detail::fork_generation;

/// Sends that find waiters registered but the doorbell not armed, before a publisher looks for
/// waiters that died (a waiter draining messages is registered and unarmed too).
inline constexpr std::uint32_t kStaleCheck = 4096;

/// A waiter's first sleep after it registered is at most this long (see the race above).
inline constexpr std::chrono::milliseconds kFirstSlice{10};

/// The publisher's side, after a send found waiters: clears the armed bits of `classes`
/// (Doorbell::kArmed*) and wakes the sleepers of those classes; false (and nothing done) when
/// none of them is armed. Async-signal-safe (atomics and one syscall), but for the first ring
/// of a process that finds a network engine armed (it maps the engines' board).
bool ring_doorbell(Doorbell& bell, std::uint32_t classes = Doorbell::kArmedAll) noexcept;

/// One thing a waiter waits for: a doorbell, an optional per-entry share of its count (a
/// subscriber entry's; null for a Trigger), and the test that ends the wait.
struct WaitItem {
  Doorbell* bell = nullptr;
  WaitShare* share = nullptr;
  bool (*ready)(const void* ctx) noexcept = nullptr;
  const void* ctx = nullptr;
  /// The waiter's class: kArmedReader (a network engine waits as kArmedBridge, not through
  /// wait_any: engine_join); wait_any with several items waits as a reader.
  std::uint32_t armed = Doorbell::kArmedReader;
};

/// A network engine (engine_board.hpp) bridging the topic of `bell`: registers as one waiter of
/// the bridge class that sleeps elsewhere (`forward`), with the share of its export entry, and
/// arms. Stays registered until engine_leave(), which takes the registration and the forward
/// back (the forward only if it is still `forward`).
void engine_join(Doorbell& bell, WaitShare& share, std::uint64_t forward) noexcept;
void engine_leave(Doorbell& bell, WaitShare& share, std::uint64_t forward) noexcept;
/// Arms the bridge class again after a wake-up took it (then look at the ring, then sleep).
void arm_bridge(Doorbell& bell) noexcept;

/// The largest number of items one wait_any call sleeps on (the kernel's futex_waitv limit).
inline constexpr std::size_t kMaxWaitItems = 128;

/// Waits until some item is ready or `deadline` passes (steady_clock::time_point::max(): no
/// deadline). Returns whether an item was ready when it returned. At most kMaxWaitItems items.
/// Kernels without futex_waitv (before 5.16) wait on several items in 1 ms slices.
bool wait_any(std::span<const WaitItem> items, std::chrono::steady_clock::time_point deadline) noexcept;

}  // namespace horus::shm

HORUS_API_END
