#include "duet/follow/noise_scaled_levels.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "forward_common.h"

namespace duet {

namespace {

// A usable noise estimate: finite and >= 0 (0 otherwise).
double usable(float noise) noexcept {
  return std::isfinite(noise) ? std::max(0.0, double{noise}) : 0.0;
}

}  // namespace

NoiseScaledLevels::NoiseScaledLevels(const FollowParams& params, int num_dims)
    : dims_(num_dims),
      sigma_sq_(double{params.emission_sigma} * params.emission_sigma),
      emission_noise_factor_(params.emission_noise_factor),
      emission_noise_allowance_(params.emission_noise_allowance),
      pause_distance_per_dim_(params.pause_distance_per_dim),
      pause_noise_factor_(params.pause_noise_factor),
      pause_noise_allowance_(params.pause_noise_allowance),
      lost_ceiling_per_dim_(params.lost_distance_per_dim),
      lost_residual_per_dim_(params.lost_residual_per_dim),
      lost_noise_factor_(params.lost_noise_factor),
      lost_residual_factor_(params.lost_residual_factor) {}

float NoiseScaledLevels::inv_two_sigma_sq(float noise) const noexcept {
  // Sigma was chosen on input with up to 3 degrees of noise (on every rig): only what exceeds
  // that widens the emission.
  const double excess = std::max(0.0, usable(noise) - emission_noise_allowance_);
  return static_cast<float>(0.5 / (sigma_sq_ + emission_noise_factor_ * excess));
}

double NoiseScaledLevels::pause_per_dim(float noise) const noexcept {
  return pause_distance_per_dim_ +
         pause_noise_factor_ * std::max(0.0, usable(noise) - pause_noise_allowance_);
}

float NoiseScaledLevels::log_pause_emission(float noise) const noexcept {
  return static_cast<float>(
      std::max(-pause_per_dim(noise) * dims_ * double{inv_two_sigma_sq(noise)},
               double{follow_detail::kMinLogEmission}));
}

float NoiseScaledLevels::pause_distance_sq(float noise) const noexcept {
  return static_cast<float>(std::min(pause_per_dim(noise) * dims_, double{FLT_MAX}));
}

float NoiseScaledLevels::lost_distance_sq(float noise, float residual) const noexcept {
  const double n = usable(noise);
  const double r = std::isfinite(residual) ? std::max(0.0, double{residual}) : 0.0;
  // +inf residual (the paper's preset) leaves the fixed ceiling alone.
  const double per_dim = std::min(
      lost_ceiling_per_dim_,
      std::max(lost_residual_per_dim_ + lost_noise_factor_ * n, lost_residual_factor_ * r));
  return static_cast<float>(std::min(per_dim * dims_, double{FLT_MAX}));
}

float NoiseScaledLevels::lost_ceiling_sq() const noexcept {
  return static_cast<float>(std::min(lost_ceiling_per_dim_ * dims_, double{FLT_MAX}));
}

}  // namespace duet
