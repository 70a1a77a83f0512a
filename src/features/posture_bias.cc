#include "duet/features/posture_bias.h"

#include <algorithm>
#include <cmath>

namespace duet {
namespace {

// The root mean square of `count` values whose squares sum to sum_squares (0 for none).
float root_mean_square(double sum_squares, std::size_t count) {
  return count == 0 ? 0.0f
                    : static_cast<float>(std::sqrt(sum_squares / static_cast<double>(count)));
}

}  // namespace

PostureBias::PostureBias(int begin, int size, const PostureBiasParams& params)
    : begin_(begin),
      params_(params),
      mean_(static_cast<std::size_t>(std::max(size, 0)), 0.0f),
      offset_(mean_.size(), 0.0f) {}

void PostureBias::correct(std::span<float> features) const noexcept {
  if (!params_.enabled) return;
  for (std::size_t d = 0; d < offset_.size(); ++d) {
    features[static_cast<std::size_t>(begin_) + d] -= offset_[d];
  }
}

void PostureBias::learn(std::span<const float> corrected, std::span<const float> matched,
                        double dt_s, float confidence, float sensor_noise) noexcept {
  if (!params_.enabled || !(dt_s > 0.0) || !std::isfinite(dt_s) || !std::isfinite(confidence) ||
      !std::isfinite(sensor_noise)) {
    return;
  }
  for (std::size_t d = 0; d < offset_.size(); ++d) {
    const std::size_t i = static_cast<std::size_t>(begin_) + d;
    if (!std::isfinite(corrected[i] - matched[i])) return;
  }
  // A running mean while little has been seen (the time constant grows with the time learnt), then
  // a first-order low-pass: mean += a * (residual - mean), a = 1 - exp(-dt / tau). Frames the
  // follower is unsure of count less, but still count: a rig far from the library's leaves every
  // frame unsure until the offset is learnt.
  const double weight = std::max(static_cast<double>(confidence), params_.min_weight);
  learnt_s_ += weight * dt_s;
  const double tau = std::min(params_.time_constant(sensor_noise), learnt_s_);
  const auto rate = static_cast<float>(weight * (1.0 - std::exp(-dt_s / tau)));
  // The running mean of white noise of variance s^2 has variance s^2 a / (2 - a).
  const double mean_variance =
      std::max(0.0, static_cast<double>(sensor_noise)) * rate / (2.0 - rate);
  const double k_squared = params_.shrink_k * params_.shrink_k;
  double sum_squares = 0.0;
  for (std::size_t d = 0; d < offset_.size(); ++d) {
    const std::size_t i = static_cast<std::size_t>(begin_) + d;
    const float residual = corrected[i] + offset_[d] - matched[i];  // input - matched
    mean_[d] = std::clamp(mean_[d] + rate * (residual - mean_[d]), -params_.max_offset,
                          params_.max_offset);
    const double mean_squared = static_cast<double>(mean_[d]) * mean_[d];
    const double keep =
        mean_squared > 0.0 ? std::max(0.0, 1.0 - k_squared * mean_variance / mean_squared) : 0.0;
    offset_[d] = static_cast<float>(mean_[d] * keep);
    sum_squares += static_cast<double>(offset_[d]) * offset_[d];
  }
  offset_rms_ = root_mean_square(sum_squares, offset_.size());
}

double PostureBiasParams::time_constant(float sensor_noise) const noexcept {
  if (!(sensor_noise > 0.0f) || !(noisy_time_constant_level > 0.0f)) return time_constant_s;
  const double scaled = noisy_time_constant_s *
                        std::sqrt(static_cast<double>(sensor_noise / noisy_time_constant_level));
  return std::clamp(scaled, time_constant_s, std::max(time_constant_s, noisy_time_constant_s));
}

float PostureBiasParams::learn_distance_limit(float sensor_noise) const noexcept {
  if (!(sensor_noise > 0.0f) || !(noisy_learn_level > 0.0f)) return max_learn_distance_per_dim;
  const float noisy = std::min(sensor_noise / noisy_learn_level, 1.0f);
  const float narrowed = max_learn_distance_per_dim +
                         noisy * (max_learn_distance_noisy_per_dim - max_learn_distance_per_dim);
  // Never wider than a steady sensor's limit: a noise estimate thrown high by input no take
  // explains must not open the offset to it.
  return std::max(narrowed,
                  std::min(learn_noise_factor * sensor_noise, max_learn_distance_per_dim));
}

void PostureBias::reset() noexcept {
  std::ranges::fill(mean_, 0.0f);
  std::ranges::fill(offset_, 0.0f);
  offset_rms_ = 0.0f;
  learnt_s_ = 0.0;
  lost_s_ = 0.0;
  found_s_ = 0.0;
}

void PostureBias::adopt(std::span<const float> offset, double seconds) noexcept {
  if (!params_.enabled || offset.size() != mean_.size()) return;
  for (std::size_t d = 0; d < mean_.size(); ++d) {
    if (!std::isfinite(offset[d])) return;
  }
  double sum_squares = 0.0;
  for (std::size_t d = 0; d < mean_.size(); ++d) {
    mean_[d] = std::clamp(mean_[d] + offset[d], -params_.max_offset, params_.max_offset);
    offset_[d] = mean_[d];
    sum_squares += static_cast<double>(offset_[d]) * offset_[d];
  }
  offset_rms_ = root_mean_square(sum_squares, offset_.size());
  learnt_s_ = std::max(learnt_s_, std::isfinite(seconds) ? seconds : 0.0);
  lost_s_ = 0.0;
  found_s_ = 0.0;
}

void PostureBias::note_lost(bool lost, double dt_s) noexcept {
  const double frame_s = dt_s > 0.0 && std::isfinite(dt_s) ? dt_s : 0.0;
  if (!lost) {
    // A run lost is broken only by frames followed for release_found_s in a row.
    found_s_ += frame_s;
    if (found_s_ + 1e-9 >= params_.release_found_s) lost_s_ = 0.0;
    return;
  }
  found_s_ = 0.0;
  if (frame_s == 0.0) return;
  lost_s_ += frame_s;
  if (!(params_.release_after_lost_s > 0.0) || lost_s_ < params_.release_after_lost_s) return;
  if (offset_rms_ > params_.release_offset_rms) reset();
}

}  // namespace duet
