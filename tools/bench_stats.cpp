#include "bench_stats.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>

namespace horus::tools {

// Group 0 holds 0..kSub-1 exactly; group g >= 1 holds [kSub << (g-1), kSub << g) in kSub
// buckets of width 2^(g-1).
std::size_t LatencyHistogram::index(std::uint64_t v) noexcept {
  if (v < kSub) return static_cast<std::size_t>(v);
  const int g = static_cast<int>(std::bit_width(v)) - kSubBits;  // >= 1
  const std::uint64_t sub = (v >> (g - 1)) - kSub;
  return static_cast<std::size_t>(g) * kSub + static_cast<std::size_t>(sub);
}

std::uint64_t LatencyHistogram::lower(std::size_t i) noexcept {
  const std::size_t g = i / kSub, sub = i % kSub;
  if (g == 0) return sub;
  return (kSub + sub) << (g - 1);
}

std::uint64_t LatencyHistogram::upper(std::size_t i) noexcept {
  const std::size_t g = i / kSub;
  return lower(i) + (g == 0 ? 1 : std::uint64_t{1} << (g - 1));
}

void LatencyHistogram::add(std::uint64_t ns) noexcept {
  ++counts_[index(ns)];
  if (count_ == 0 || ns < min_) min_ = ns;
  max_ = std::max(max_, ns);
  ++count_;
  const auto d = static_cast<double>(ns);
  sum_ += d;
  sum_sq_ += d * d;
  if (has_last_) {
    sum_delta_ += std::fabs(d - static_cast<double>(last_));
    ++deltas_;
  }
  last_ = ns;
  has_last_ = true;
}

void LatencyHistogram::clear() noexcept { *this = LatencyHistogram{}; }

void LatencyHistogram::merge(const LatencyHistogram& o) noexcept {
  if (o.count_ == 0) return;
  for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += o.counts_[i];
  min_ = count_ == 0 ? o.min_ : std::min(min_, o.min_);
  max_ = std::max(max_, o.max_);
  count_ += o.count_;
  sum_ += o.sum_;
  sum_sq_ += o.sum_sq_;
  sum_delta_ += o.sum_delta_;
  deltas_ += o.deltas_;
}

double LatencyHistogram::mean() const noexcept { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }

double LatencyHistogram::stddev() const noexcept {
  if (count_ < 2) return 0.0;
  const double m = mean();
  const double var = sum_sq_ / static_cast<double>(count_) - m * m;
  return var > 0 ? std::sqrt(var) : 0.0;
}

double LatencyHistogram::jitter() const noexcept {
  return deltas_ ? sum_delta_ / static_cast<double>(deltas_) : 0.0;
}

std::uint64_t LatencyHistogram::quantile(double q) const noexcept {
  if (count_ == 0) return 0;
  q = std::clamp(q, 0.0, 1.0);
  const auto rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_))));
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < counts_.size(); ++i) {
    seen += counts_[i];
    if (seen >= rank) {
      const std::uint64_t mid = lower(i) + (upper(i) - lower(i)) / 2;
      return std::clamp(mid, min_, max_);
    }
  }
  return max_;
}

std::vector<LatencyHistogram::Bucket> LatencyHistogram::buckets() const {
  std::vector<Bucket> out;
  for (std::size_t i = 0; i < counts_.size(); ++i)
    if (counts_[i] != 0) out.push_back({lower(i), upper(i), counts_[i]});
  return out;
}

std::string format_ns(double ns) {
  auto three = [](double v, const char* unit) {
    const int decimals = v >= 100 ? 0 : v >= 10 ? 1 : 2;
    return fmt::format("{:.{}f} {}", v, decimals, unit);
  };
  if (ns < 1000) return fmt::format("{:.0f} ns", ns);
  if (ns < 1e6) return three(ns / 1e3, "us");
  if (ns < 1e9) return three(ns / 1e6, "ms");
  return three(ns / 1e9, "s");
}

}  // namespace horus::tools
