// Latency percentiles without storing samples: a log-linear histogram of microseconds (1 us bins up
// to 1 ms, then 128 bins per power of two, under 1% relative error), fixed size, no allocation
// after construction. Not thread-safe: one thread records and reads.
#pragma once

#include <array>
#include <cstdint>

namespace duet::net {

class LatencyHistogram {
 public:
  void record(std::int64_t microseconds) noexcept;
  void clear() noexcept;
  // Adds another histogram's samples (e.g. a window into a running total).
  void merge(const LatencyHistogram& other) noexcept;

  std::int64_t count() const noexcept { return count_; }
  // The smallest value v such that at least fraction q of the samples are <= v (bin upper bound,
  // so never below the true percentile); 0 without samples. q in [0, 1].
  std::int64_t percentile(double q) const noexcept;
  std::int64_t max() const noexcept { return max_; }

 private:
  static constexpr int kLinear = 1024;  // 1 us bins for [0, 1024) us
  static constexpr int kSubBins = 128;  // per power of two above
  static constexpr int kOctaves = 32;   // up to 2^42 us
  static constexpr int kBins = kLinear + kOctaves * kSubBins;
  static int bin_of(std::int64_t us) noexcept;
  static std::int64_t upper_bound_of(int bin) noexcept;

  std::array<std::uint32_t, kBins> bins_{};
  std::int64_t count_ = 0;
  std::int64_t max_ = 0;
};

}  // namespace duet::net
