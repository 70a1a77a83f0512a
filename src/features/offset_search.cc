#include "duet/features/offset_search.h"

#include <algorithm>
#include <cmath>

namespace duet {

OffsetSearch::OffsetSearch(int posture_begin, int posture_size, int dimension)
    : posture_begin_(posture_begin),
      dimension_(dimension),
      mean_(static_cast<std::size_t>(std::max(posture_size, 0)), 0.0f),
      matched_mean_(mean_.size(), 0.0f) {}

void OffsetSearch::reset() noexcept {
  std::ranges::fill(mean_, 0.0f);
  std::ranges::fill(matched_mean_, 0.0f);
  motion_ = 0.0;
  seen_s_ = 0.0;
  held_s_ = 0.0;
  explained_ = 0.0;
}

bool OffsetSearch::observe(std::span<const float> input, std::span<const float> matched,
                           bool continues, float limit, double dt_s,
                           const OffsetSearchParams& params) noexcept {
  if (!params.enabled || dimension_ <= 0 || !(dt_s > 0.0) || !std::isfinite(dt_s) ||
      !std::isfinite(limit)) {
    return false;
  }
  for (std::size_t d = 0; d < static_cast<std::size_t>(dimension_); ++d) {
    if (!std::isfinite(input[d] - matched[d])) return false;
  }
  // The distance this frame would have had with the trial removed, the trial as learnt before it
  // (out of sample: a trial fitted to the frame itself explains any one frame).
  const auto begin = static_cast<std::size_t>(posture_begin_);
  const std::size_t end = begin + mean_.size();
  double squares = 0.0;
  for (std::size_t d = 0; d < static_cast<std::size_t>(dimension_); ++d) {
    const float trial = d >= begin && d < end ? mean_[d - begin] : 0.0f;
    const double r = static_cast<double>(input[d] - matched[d] - trial);
    squares += r * r;
  }
  const double distance = squares / static_cast<double>(dimension_);
  seen_s_ += dt_s;
  const double tau = std::min(params.time_constant_s, seen_s_);
  const double rate = 1.0 - std::exp(-dt_s / tau);
  double moved = 0.0;
  for (std::size_t d = begin; d < end; ++d) {
    float& mean = mean_[d - begin];
    mean += static_cast<float>(rate) * (input[d] - matched[d] - mean);
    const double m = static_cast<double>(matched[d] - matched_mean_[d - begin]);
    moved += m * m;
    matched_mean_[d - begin] += static_cast<float>(rate) * (matched[d] - matched_mean_[d - begin]);
  }
  motion_ += rate * (moved / static_cast<double>(dimension_) - motion_);
  explained_ += rate * (distance - explained_);
  // Only frames on an unbroken path count towards the hold (the best frame flickers between
  // look-alike places of other takes; they neither count nor restart it).
  if (explained_ > static_cast<double>(limit)) {
    held_s_ = 0.0;
  } else if (continues) {
    held_s_ += dt_s;
  }
  return held_s_ >= params.hold_s && motion_ >= params.min_motion_per_dim;
}

}  // namespace duet
