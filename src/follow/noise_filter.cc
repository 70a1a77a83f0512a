#include "duet/follow/noise_filter.h"

#include <algorithm>
#include <cmath>

namespace duet {

namespace {

// The velocity's variance at the first frame: unknown, so large against any dance's (standardised
// features move by a few units a second at most).
constexpr double kUnknownVelocityVariance = 100.0;
// Longer gaps than this start over: a second without input says little about the motion.
constexpr double kMaxGapS = 1.0;
// Restart when the squared innovation, averaged over the dimensions, exceeds this many times its
// expected variance (the average of many chi-square(1) terms stays near 1: 9 is no noise).
constexpr double kRestartInnovations = 9.0;

}  // namespace

NoiseFilter::NoiseFilter(int num_dims, int posture_dims, double acceleration_density,
                         double noise_allowance, double template_fps)
    : dims_(std::clamp(posture_dims, 0, std::max(num_dims, 0))),
      density_(std::isfinite(acceleration_density) ? std::max(acceleration_density, 0.0) : 0.0),
      allowance_(std::isfinite(noise_allowance) ? std::max(noise_allowance, 0.0) : 0.0),
      default_dt_s_(template_fps > 0.0 ? 1.0 / template_fps : 1.0 / 60.0),
      position_(static_cast<std::size_t>(dims_), 0.0),
      velocity_(static_cast<std::size_t>(dims_), 0.0),
      out_(static_cast<std::size_t>(std::max(num_dims, 0)), 0.0f) {}

void NoiseFilter::reset() noexcept {
  started_ = false;
  gain_ = 1.0;
  gap_s_ = 0.0;
}

void NoiseFilter::start(std::span<const float> features, double noise_variance) noexcept {
  for (std::size_t d = 0; d < static_cast<std::size_t>(dims_); ++d) {
    position_[d] = features[d];
    velocity_[d] = 0.0;
  }
  p00_ = noise_variance;
  p01_ = 0.0;
  p11_ = kUnknownVelocityVariance;
  started_ = true;
  gain_ = 1.0;
}

void NoiseFilter::miss(double dt_s) noexcept {
  gap_s_ += dt_s > 0.0 && std::isfinite(dt_s) ? dt_s : default_dt_s_;
}

std::span<const float> NoiseFilter::apply(std::span<const float> features, double dt_s,
                                          float noise_variance) noexcept {
  if (density_ <= 0.0 || dims_ == 0 || features.size() != out_.size()) return features;
  std::copy(features.begin(), features.end(), out_.begin());
  const auto dims = static_cast<std::size_t>(dims_);
  // Below the allowance the input passes: a clean sensor's estimate is the dance's own
  // acceleration, and smoothing that only adds lag.
  const double r = std::isfinite(noise_variance)
                       ? std::max(0.0, static_cast<double>(noise_variance) - allowance_)
                       : 0.0;
  const double dt = (dt_s > 0.0 && std::isfinite(dt_s) ? dt_s : default_dt_s_) + gap_s_;
  gap_s_ = 0.0;
  if (!started_ || dt > kMaxGapS) {
    start(features, r);
    return out_;
  }
  // Predict over dt (white acceleration), then weigh the new frame against the prediction.
  const double q = density_;
  const double p00 = p00_ + 2.0 * dt * p01_ + dt * dt * p11_ + q * dt * dt * dt / 3.0;
  const double p01 = p01_ + dt * p11_ + q * dt * dt / 2.0;
  const double p11 = p11_ + q * dt;
  const double s = p00 + r;
  // An input that left the prediction by far more than the noise and the motion explain (a
  // glitch, or the sensor back after something else) starts the filter over at it: carried on,
  // the old place would be blended into the new one for many frames.
  double innovation_sq = 0.0;
  for (std::size_t d = 0; d < dims; ++d) {
    const double innovation =
        static_cast<double>(features[d]) - (position_[d] + velocity_[d] * dt);
    innovation_sq += innovation * innovation;
  }
  if (!(innovation_sq <= kRestartInnovations * s * static_cast<double>(dims))) {
    start(features, r);
    return out_;
  }
  const double k0 = s > 0.0 && r > 0.0 ? p00 / s : 1.0;
  const double k1 = s > 0.0 ? p01 / s : 0.0;
  for (std::size_t d = 0; d < dims; ++d) {
    const double predicted = position_[d] + velocity_[d] * dt;
    const double innovation = static_cast<double>(features[d]) - predicted;
    velocity_[d] += k1 * innovation;
    if (k0 < 1.0) {
      position_[d] = predicted + k0 * innovation;
      out_[d] = static_cast<float>(position_[d]);
    } else {
      position_[d] = features[d];  // no noise to remove: the input exactly, not rounded twice
    }
  }
  p00_ = (1.0 - k0) * p00;
  p01_ = (1.0 - k0) * p01;
  p11_ = p11 - k1 * p01;
  gain_ = k0;
  return out_;
}

}  // namespace duet
