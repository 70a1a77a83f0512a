#include "duet/net/latency_histogram.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace duet::net {

int LatencyHistogram::bin_of(std::int64_t us) noexcept {
  if (us < kLinear) return static_cast<int>(std::max<std::int64_t>(us, 0));
  const auto v = static_cast<std::uint64_t>(us);
  const int octave = static_cast<int>(std::bit_width(v)) - 1;  // >= 10
  const int sub = static_cast<int>((v >> (octave - 7)) & (kSubBins - 1));
  const int bin = kLinear + (octave - 10) * kSubBins + sub;
  return std::min(bin, kBins - 1);
}

std::int64_t LatencyHistogram::upper_bound_of(int bin) noexcept {
  if (bin < kLinear) return bin;
  const int octave = (bin - kLinear) / kSubBins + 10;
  const int sub = (bin - kLinear) % kSubBins;
  // Values in this bin: [(128 + sub) << (octave - 7), (129 + sub) << (octave - 7)).
  return ((static_cast<std::int64_t>(kSubBins + sub + 1)) << (octave - 7)) - 1;
}

void LatencyHistogram::record(std::int64_t microseconds) noexcept {
  microseconds = std::max<std::int64_t>(microseconds, 0);
  ++bins_[static_cast<std::size_t>(bin_of(microseconds))];
  ++count_;
  max_ = std::max(max_, microseconds);
}

void LatencyHistogram::clear() noexcept {
  bins_.fill(0);
  count_ = 0;
  max_ = 0;
}

void LatencyHistogram::merge(const LatencyHistogram& other) noexcept {
  for (std::size_t i = 0; i < bins_.size(); ++i) bins_[i] += other.bins_[i];
  count_ += other.count_;
  max_ = std::max(max_, other.max_);
}

std::int64_t LatencyHistogram::percentile(double q) const noexcept {
  if (count_ == 0) return 0;
  q = std::clamp(q, 0.0, 1.0);
  const auto rank = std::max<std::int64_t>(
      1, static_cast<std::int64_t>(std::ceil(q * static_cast<double>(count_))));
  std::int64_t seen = 0;
  for (int bin = 0; bin < kBins; ++bin) {
    seen += bins_[static_cast<std::size_t>(bin)];
    if (seen >= rank) return std::min(upper_bound_of(bin), max_);
  }
  return max_;
}

}  // namespace duet::net
