// The futex calls behind Doorbell (the protocol is described in doorbell.hpp).
#include "horus/shm/doorbell.hpp"

#include "horus/shm/engine_board.hpp"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <ctime>

namespace horus::shm {

namespace {
using Clock = std::chrono::steady_clock;  // CLOCK_MONOTONIC, the clock the futex deadlines use

int private_flag(const Doorbell& b) noexcept { return b.process_private != 0 ? FUTEX_PRIVATE_FLAG : 0; }

timespec to_timespec(Clock::time_point t) noexcept {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  return timespec{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}

std::atomic<bool> g_no_waitv{false};  // the kernel said ENOSYS once

// The bitset a waiter of class `armed` sleeps with: readers wake for every ring, a bridge's
// export thread only for rings that name its class.
std::uint32_t wait_bitset(std::uint32_t armed) noexcept {
  return armed == Doorbell::kArmedReader ? FUTEX_BITSET_MATCH_ANY : armed;
}

// Sleeps on one word while it holds `val`, until `until` (max: no deadline).
void sleep_one(Doorbell& b, std::uint32_t val, Clock::time_point until, std::uint32_t armed) noexcept {
  const timespec ts = to_timespec(until);
  ::syscall(SYS_futex, &b.word, FUTEX_WAIT_BITSET | private_flag(b), val,
            until == Clock::time_point::max() ? nullptr : &ts, nullptr, wait_bitset(armed));
}

// Sleeps on several words at once; false when the kernel has no futex_waitv.
bool sleep_many(const futex_waitv* v, std::size_t n, Clock::time_point until) noexcept {
  const timespec ts = to_timespec(until);
  const long r = ::syscall(SYS_futex_waitv, v, static_cast<unsigned>(n), 0u,
                           until == Clock::time_point::max() ? nullptr : &ts, CLOCK_MONOTONIC);
  if (r < 0 && errno == ENOSYS) {
    g_no_waitv.store(true, std::memory_order_relaxed);
    return false;
  }
  return true;
}

bool any_ready(std::span<const WaitItem> items) noexcept {
  return std::any_of(items.begin(), items.end(), [](const WaitItem& it) { return it.ready(it.ctx); });
}

// Sets the armed bit of class `armed` (unless set) and returns the word's value with it.
std::uint32_t arm(Doorbell& b, std::uint32_t armed) noexcept {
  std::uint32_t w = b.word.load(std::memory_order_acquire);
  while ((w & armed) == 0 && !b.word.compare_exchange_weak(w, w | armed, std::memory_order_seq_cst)) {
  }
  return w | armed;
}

// Takes one registration back: from the entry's share when it still holds it (the reaper or
// an unsubscribe may have taken the whole share back already, with the count).
void unregister(const WaitItem& it) noexcept {
  if (it.share != nullptr) {
    std::uint32_t n = it.share->count.load(std::memory_order_relaxed);
    while (n != 0 && !it.share->count.compare_exchange_weak(n, n - 1, std::memory_order_acq_rel)) {
    }
    if (n == 0) return;
  }
  it.bell->state.fetch_sub(Doorbell::kWaiter, std::memory_order_acq_rel);
}
}  // namespace

bool ring_doorbell(Doorbell& bell, std::uint32_t classes) noexcept {
  // The publisher stored its message (the lane head) before calling this; a waiter arms the word
  // (a seq_cst read-modify-write) and then looks at the heads. Without a full fence between our
  // head store and this load, both could read the old value (store buffering): we would see the
  // word unarmed and the waiter the ring empty, and it would sleep with our message unseen until
  // the next send or its deadline. Paid only when a waiter is registered.
#if defined(__SANITIZE_THREAD__)
  std::uint32_t w = bell.word.fetch_add(0, std::memory_order_seq_cst);  // TSan does not model fences
#else
  std::atomic_thread_fence(std::memory_order_seq_cst);
  std::uint32_t w = bell.word.load(std::memory_order_relaxed);
#endif
  while ((w & classes) != 0) {
    // Disarm those classes and start a new epoch: exactly one publisher makes the syscall. A
    // class left armed stays armed (its sleepers are not woken, the next ring of it finds them).
    if (bell.word.compare_exchange_weak(w, (w & ~classes) + Doorbell::kEpoch, std::memory_order_acq_rel,
                                        std::memory_order_relaxed)) {
      const std::uint32_t woken = w & classes;
      // The readers first: a local subscriber's latency must not include the network engine's
      // wake-up and export. Woken second, the engine found the CPU the subscriber was given
      // taken (on 2 vCPUs it was queued behind the engine's DDS write: 7x a host topic).
      if ((woken & Doorbell::kArmedReader) != 0)
        ::syscall(SYS_futex, &bell.word, FUTEX_WAKE_BITSET | private_flag(bell), INT_MAX, nullptr, nullptr,
                  static_cast<std::uint32_t>(Doorbell::kArmedReader));
      if ((woken & Doorbell::kArmedBridge) != 0) {
        // A network engine sleeps on its own word (engine_board.hpp): wake it there. A forward
        // whose engine is gone falls back to the word (nobody of that class sleeps there).
        const std::uint64_t forward = bell.forward.load(std::memory_order_acquire);
        if (forward == 0 || !notify_engine(forward))
          ::syscall(SYS_futex, &bell.word, FUTEX_WAKE_BITSET | private_flag(bell), INT_MAX, nullptr, nullptr,
                    static_cast<std::uint32_t>(Doorbell::kArmedBridge));
      }
      return true;
    }
  }
  return false;
}

void engine_join(Doorbell& bell, WaitShare& share, std::uint64_t forward) noexcept {
  bell.forward.store(forward, std::memory_order_release);
  bell.state.fetch_add(Doorbell::kWaiter, std::memory_order_seq_cst);
  share.pid.store(static_cast<std::int32_t>(::getpid()), std::memory_order_relaxed);
  share.count.fetch_add(1, std::memory_order_seq_cst);
  arm_bridge(bell);
}

void engine_leave(Doorbell& bell, WaitShare& share, std::uint64_t forward) noexcept {
  std::uint64_t mine = forward;
  bell.forward.compare_exchange_strong(mine, 0, std::memory_order_acq_rel);
  unregister(WaitItem{&bell, &share, nullptr, nullptr, Doorbell::kArmedBridge});
}

void arm_bridge(Doorbell& bell) noexcept {
  (void)arm(bell, Doorbell::kArmedBridge);
#if !defined(__SANITIZE_THREAD__)
  std::atomic_thread_fence(std::memory_order_seq_cst);  // pairs with ring_doorbell's: look after this
#endif
}

bool wait_any(std::span<const WaitItem> items, Clock::time_point deadline) noexcept {
  if (any_ready(items)) return true;
  if (items.empty() || Clock::now() >= deadline) return false;
  const std::size_t n = std::min(items.size(), kMaxWaitItems);
  for (std::size_t i = 0; i < n; ++i) {
    items[i].bell->state.fetch_add(Doorbell::kWaiter, std::memory_order_seq_cst);
    if (items[i].share != nullptr) {
      items[i].share->pid.store(static_cast<std::int32_t>(::getpid()), std::memory_order_relaxed);
      items[i].share->count.fetch_add(1, std::memory_order_seq_cst);
    }
  }
  futex_waitv v[kMaxWaitItems];
  bool ready = false;
  bool first = true;
  for (;;) {
    for (std::size_t i = 0; i < n; ++i) {
      Doorbell& b = *items[i].bell;
      // Several items wait as readers (futex_waitv has no bitset: any ring wakes it).
      v[i] = futex_waitv{arm(b, n == 1 ? items[i].armed : Doorbell::kArmedReader), reinterpret_cast<std::uintptr_t>(&b.word),
                         static_cast<std::uint32_t>(FUTEX_32 | private_flag(b)), 0};
    }
    // Armed: any publisher from now on rings. Look once more before sleeping (the fence pairs
    // with ring_doorbell's; arm's compare-exchange is one already unless the word was armed).
#if !defined(__SANITIZE_THREAD__)
    std::atomic_thread_fence(std::memory_order_seq_cst);
#endif
    if (any_ready(items)) {
      ready = true;
      break;
    }
    const auto now = Clock::now();
    if (now >= deadline) break;
    auto until = deadline;
    if (first) until = std::min(deadline, now + kFirstSlice);
    first = false;
    if (n == 1) {
      sleep_one(*items[0].bell, static_cast<std::uint32_t>(v[0].val), until, items[0].armed);
    } else if (g_no_waitv.load(std::memory_order_relaxed) || !sleep_many(v, n, until)) {
      // No futex_waitv: sleep on the first item, looking at the others every millisecond.
      sleep_one(*items[0].bell, static_cast<std::uint32_t>(v[0].val),
                std::min(until, Clock::now() + std::chrono::milliseconds(1)), Doorbell::kArmedReader);
    }
  }
  for (std::size_t i = 0; i < n; ++i) unregister(items[i]);
  return ready;
}

}  // namespace horus::shm
