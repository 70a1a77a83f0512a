#include "duet/features/posture_bias.h"

#include <algorithm>
#include <cmath>

namespace duet {

PostureBias::PostureBias(int begin, int size, const PostureBiasParams& params)
    : begin_(begin), params_(params), offset_(static_cast<std::size_t>(std::max(size, 0)), 0.0f) {}

void PostureBias::correct(std::span<float> features) const noexcept {
  if (!params_.enabled) return;
  for (std::size_t d = 0; d < offset_.size(); ++d) {
    features[static_cast<std::size_t>(begin_) + d] -= offset_[d];
  }
}

void PostureBias::learn(std::span<const float> corrected, std::span<const float> matched,
                        double dt_s, float confidence) noexcept {
  if (!params_.enabled || !(dt_s > 0.0) || !std::isfinite(dt_s) || !std::isfinite(confidence)) {
    return;
  }
  // A running mean while little has been seen (the time constant grows with the time learnt), then
  // a first-order low-pass: offset += a * residual, a = 1 - exp(-dt / tau). Frames the follower is
  // unsure of count less, but still count: a rig far from the library's leaves every frame unsure
  // until the offset is learnt.
  const double weight = std::max(static_cast<double>(confidence), params_.min_weight);
  learnt_s_ += weight * dt_s;
  const double tau = std::min(params_.time_constant_s, learnt_s_);
  const auto rate = static_cast<float>(weight * (1.0 - std::exp(-dt_s / tau)));
  for (std::size_t d = 0; d < offset_.size(); ++d) {
    const std::size_t i = static_cast<std::size_t>(begin_) + d;
    const float residual = corrected[i] - matched[i];
    if (!std::isfinite(residual)) return;
    offset_[d] = std::clamp(offset_[d] + rate * residual, -params_.max_offset, params_.max_offset);
  }
}

void PostureBias::reset() noexcept {
  std::ranges::fill(offset_, 0.0f);
  learnt_s_ = 0.0;
}

}  // namespace duet
