// Shared pieces of the benchmarks: a TSC clock and percentiles (CPU pinning and the true floor:
// horus/detail/cache_floor.hpp, which `horus bench local` uses too).
#pragma once

#include <pthread.h>
#include <sched.h>
#include <x86intrin.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <thread>
#include <utility>
#include <vector>

#include "horus/detail/cache_floor.hpp"  // pin_to_cpu, the true floor

namespace horus::bench {

inline int cpu_count() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

/// Time-stamp counter ticks converted to nanoseconds (calibrated against steady_clock).
class TscClock {
 public:
  TscClock() {
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    const std::uint64_t c0 = __rdtsc();
    while (clock::now() - t0 < std::chrono::milliseconds(100)) {
    }
    const auto t1 = clock::now();
    const std::uint64_t c1 = __rdtsc();
    ns_per_tick_ = std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(c1 - c0);
  }
  static std::uint64_t now() noexcept { return __rdtsc(); }
  double to_ns(std::uint64_t ticks) const noexcept { return static_cast<double>(ticks) * ns_per_tick_; }
  double to_ns(double ticks) const noexcept { return ticks * ns_per_tick_; }

 private:
  double ns_per_tick_ = 1.0;
};

struct Percentiles {
  double p50 = 0, p99 = 0, p999 = 0, min = 0, mean = 0;
};

/// Percentiles of samples in ns (the vector is sorted in place).
inline Percentiles percentiles(std::vector<double>& ns) {
  Percentiles p;
  if (ns.empty()) return p;
  std::sort(ns.begin(), ns.end());
  auto at = [&](double q) { return ns[std::min(ns.size() - 1, static_cast<std::size_t>(q * static_cast<double>(ns.size())))]; };
  p.p50 = at(0.50);
  p.p99 = at(0.99);
  p.p999 = at(0.999);
  p.min = ns.front();
  double sum = 0;
  for (double v : ns) sum += v;
  p.mean = sum / static_cast<double>(ns.size());
  return p;
}

/// The distribution as (quantile, value) points for a CDF plot: every percent, then 99.5, 99.9
/// and 99.99 (samples sorted, as percentiles() leaves them).
inline std::vector<std::pair<double, double>> cdf_points(const std::vector<double>& sorted) {
  std::vector<std::pair<double, double>> out;
  if (sorted.empty()) return out;
  auto at = [&](double q) {
    return sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(q * static_cast<double>(sorted.size())))];
  };
  for (int i = 0; i < 100; ++i) out.emplace_back(i / 100.0, at(i / 100.0));
  for (double q : {0.995, 0.999, 0.9999}) out.emplace_back(q, at(q));
  return out;
}

}  // namespace horus::bench
