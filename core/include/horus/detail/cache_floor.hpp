// The true floor of a one-way hand-over between two cores: what the cheapest possible
// ping-pong costs on the two CPUs a benchmark pins its measured path to.
//
// Two ways of bouncing, both measured, the better one is the floor (which wins depends on the
// CPU):
//   * one line:  ping stores 2i+1 into one word, pong answers 2i+2 in the same word (one cache
//                line changes owner each way);
//   * two lines: ping stores i into its line, pong answers i in another line 256 bytes away
//                (each side writes only its own line and reads the other's).
//
// Why the layout and the spins matter (measured on the 2-vCPU EPYC VM: a floor with its two
// words 64 B apart read 270 ns, the same two words 256 B apart with `pause` 200-205 ns):
//   * adjacent-line prefetch: CPUs fetch cache lines in aligned 128-byte pairs; two words in
//     one pair make every hand-over drag the other side's line along. Each word here has a
//     128-byte pair to itself, and the two-line words are 256 B apart.
//   * a spin without `pause` fills the pipeline with speculative loads of the watched line;
//     when the other core writes it, the CPU clears all of them (a memory-ordering machine
//     clear) before it can see the new value. `pause` keeps one load in flight.
// A floor measured without both is slower than the hardware allows, and every ratio against it
// flatters the measured path.
//
// It lives in core/ (horus/detail/cache_floor.hpp, not public API) so that the latency tools of
// bench/ and `horus bench local` (tools/) measure the floor with the same code.
#pragma once

#include <immintrin.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::bench {

/// Pins the calling thread to one CPU (false when that CPU is not available).
inline bool pin_to_cpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof(set), &set) == 0;
}

/// What every spin in a latency benchmark calls between two polls.
[[gnu::always_inline]] inline void spin_pause() noexcept { _mm_pause(); }

enum class FloorMode { OneLine, TwoLines };

inline std::string_view floor_mode_name(FloorMode m) noexcept {
  return m == FloorMode::OneLine ? "one line" : "two lines 256 B apart";
}

/// The words of the floor, each in a 128-byte pair of its own. Put it in memory both sides
/// see (a thread's heap, or a MAP_SHARED page between processes) and reset() it before a run.
struct FloorLines {
  struct alignas(128) Word {
    std::atomic<std::uint64_t> v{0};
  };
  Word one;     // the one-line bounce
  Word gap0;    // keeps `ping` out of `one`'s neighbourhood
  Word ping;    // written by the pinging side only
  Word gap1;    // `pong` is 256 B after `ping`
  Word pong;    // written by the answering side only

  void reset() noexcept {
    one.v.store(0, std::memory_order_relaxed);
    ping.v.store(0, std::memory_order_relaxed);
    pong.v.store(0, std::memory_order_relaxed);
  }
};
static_assert(sizeof(FloorLines::Word) == 128);
static_assert(offsetof(FloorLines, pong) - offsetof(FloorLines, ping) == 256);

/// Round trip i (from 0) on the pinging side: hands over and waits for the answer.
[[gnu::always_inline]] inline void floor_ping(FloorLines& l, FloorMode m, std::uint64_t i) noexcept {
  if (m == FloorMode::OneLine) {
    l.one.v.store(2 * i + 1, std::memory_order_release);
    while (l.one.v.load(std::memory_order_acquire) != 2 * i + 2) spin_pause();
  } else {
    l.ping.v.store(i + 1, std::memory_order_release);
    while (l.pong.v.load(std::memory_order_acquire) != i + 1) spin_pause();
  }
}

/// The answering side of `n` round trips.
inline void floor_echo(FloorLines& l, FloorMode m, std::uint64_t n) noexcept {
  for (std::uint64_t i = 0; i < n; ++i) {
    if (m == FloorMode::OneLine) {
      while (l.one.v.load(std::memory_order_acquire) != 2 * i + 1) spin_pause();
      l.one.v.store(2 * i + 2, std::memory_order_release);
    } else {
      while (l.ping.v.load(std::memory_order_acquire) != i + 1) spin_pause();
      l.pong.v.store(i + 1, std::memory_order_release);
    }
  }
}

}  // namespace horus::bench

HORUS_API_END
