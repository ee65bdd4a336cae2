// Latency statistics of `horus bench`: a log-linear histogram of nanosecond samples (constant
// memory for any run length; every value within 1/256 of its bucket's lower bound, so a
// percentile is within 0.4 % of the exact one), with the exact min, max, mean, standard
// deviation and jitter beside it.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace horus::tools {

class LatencyHistogram {
 public:
  /// Sub-buckets per power of two: values below kSub are exact.
  static constexpr int kSubBits = 8;
  static constexpr std::uint64_t kSub = std::uint64_t{1} << kSubBits;
  static constexpr int kGroups = 64 - kSubBits + 1;

  void add(std::uint64_t ns) noexcept;
  void clear() noexcept;
  void merge(const LatencyHistogram& o) noexcept;

  std::uint64_t count() const noexcept { return count_; }
  std::uint64_t min() const noexcept { return count_ ? min_ : 0; }
  std::uint64_t max() const noexcept { return max_; }
  double mean() const noexcept;
  double stddev() const noexcept;
  /// Mean absolute difference between consecutive samples (the RFC 3550 idea, unsmoothed).
  double jitter() const noexcept;
  /// The value at quantile q in [0, 1] (nearest rank, the bucket's middle; exact below 256 ns).
  std::uint64_t quantile(double q) const noexcept;

  /// Non-empty buckets in increasing order: (lower bound, upper bound exclusive, count).
  struct Bucket {
    std::uint64_t lo, hi, count;
  };
  std::vector<Bucket> buckets() const;

 private:
  static std::size_t index(std::uint64_t v) noexcept;
  static std::uint64_t lower(std::size_t i) noexcept;
  static std::uint64_t upper(std::size_t i) noexcept;

  std::array<std::uint64_t, kGroups * kSub> counts_{};
  std::uint64_t count_ = 0, min_ = 0, max_ = 0;
  double sum_ = 0, sum_sq_ = 0, sum_delta_ = 0;
  std::uint64_t deltas_ = 0, last_ = 0;
  bool has_last_ = false;
};

/// "812 ns", "45.3 us", "1.25 ms", "2.01 s": three significant figures.
std::string format_ns(double ns);

}  // namespace horus::tools
