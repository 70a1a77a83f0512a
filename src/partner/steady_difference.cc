#include "duet/partner/steady_difference.h"

#include <algorithm>
#include <cmath>

namespace duet {
namespace {

bool usable_step(double dt_s) { return dt_s > 0.0 && std::isfinite(dt_s); }

}  // namespace

Vec3 SteadyDifference::update(const Vec3& difference, double jitter, double jitter_reference,
                              double dt_s, const SteadyDifferenceParams& params) noexcept {
  if (!difference.allFinite()) return steady_;
  if (!std::isfinite(jitter) || jitter < 0.0) jitter = 0.0;
  // How much of the jitter is taken for the sensor's noise: none of a clean capture's 1-3 mm
  // (its own motion's), all of it well above the reference. The averaging time and the noise
  // left in the average follow it.
  const double ratio = jitter_reference > 0.0 ? jitter / jitter_reference : 0.0;
  const double noisy = ratio * ratio * ratio * ratio;
  const double noise_share = std::isfinite(noisy) ? noisy / (1.0 + noisy) : 1.0;
  const double tau = params.time_constant_s * noise_share;
  if (usable_step(dt_s)) seen_s_ += dt_s;
  // A running mean until the average has seen tau (its first sample may be all noise).
  const double alpha = tau > 0.0 && usable_step(dt_s) && seen_s_ > 0.0
                           ? std::max(1.0 - std::exp(-dt_s / tau), std::min(1.0, dt_s / seen_s_))
                           : 1.0;
  const bool first = !valid_;
  average_ = first ? difference : Vec3(average_ + alpha * (difference - average_));
  valid_ = true;
  steady_ = trust(noise_share * jitter * jitter, alpha, dt_s, first, params) * average_;
  return steady_;
}

// Over power_time_constant_s the average's mean square is the real difference's plus the noise
// left in the average: white noise of variance v through a running average of weight alpha keeps
// v alpha / (2 - alpha). The real share is 1 - noise / power.
double SteadyDifference::trust(double noise_variance, double alpha, double dt_s, bool first,
                               const SteadyDifferenceParams& params) noexcept {
  if (!(params.power_time_constant_s > 0.0)) return 1.0;
  const double square = average_.squaredNorm();
  if (first) {
    power_ = square;
  } else if (usable_step(dt_s)) {
    power_ += (1.0 - std::exp(-dt_s / params.power_time_constant_s)) * (square - power_);
  }
  const double noise = noise_variance * alpha / (2.0 - alpha);
  if (!(power_ > 0.0) || !std::isfinite(noise)) return 1.0;
  return std::clamp(1.0 - noise / power_, 0.0, 1.0);
}

}  // namespace duet
