#include "duet/live/calibration_advice.h"

#include <algorithm>
#include <cmath>

namespace duet {

void CalibrationAdvice::observe(const FollowResult& result, double dt_s) noexcept {
  if (result.missing || !(result.rig_offset_learnt_s >= kSettledOffsetS) ||
      !std::isfinite(result.rig_offset) || !(dt_s > 0.0) || !std::isfinite(dt_s)) {
    return;
  }
  const auto bin = static_cast<int>(
      std::clamp(std::floor(result.rig_offset / kResolution), 0.0f, static_cast<float>(kBins - 1)));
  ++counts_[static_cast<std::size_t>(bin)];
  ++count_;
  settled_s_ += dt_s;
}

std::optional<float> CalibrationAdvice::other_body_offset() const noexcept {
  if (count_ == 0 || settled_s_ + 1e-9 < kMinSettledS) return std::nullopt;
  // The upper median: the frame at index count_ / 2 in offset order.
  int seen = 0;
  int bin = 0;
  for (; bin < kBins; ++bin) {
    seen += counts_[static_cast<std::size_t>(bin)];
    if (seen > count_ / 2) break;
  }
  const float median = (static_cast<float>(bin) + 0.5f) * kResolution;
  if (median < kOtherBodyOffset) return std::nullopt;
  return median;
}

void CalibrationAdvice::reset() noexcept {
  counts_.fill(0);
  count_ = 0;
  settled_s_ = 0.0;
}

}  // namespace duet
