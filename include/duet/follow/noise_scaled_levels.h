// The HMM's emission scale, pause level and lost distance, scaled to the sensor's noise
// (FollowParams, issue 11): the constants come from the parameters once, the noise estimate each
// frame.
#pragma once

#include "duet/follow/follow_params.h"

namespace duet {

class NoiseScaledLevels {
 public:
  NoiseScaledLevels() = default;
  // num_dims: D of the model.
  NoiseScaledLevels(const FollowParams& params, int num_dims);

  // 1 / (2 s^2) of the emission (eq. 7) for this sensor noise: s^2 = emission_sigma^2 +
  // emission_noise_factor * noise, the template's own spread plus what the sensor adds.
  float inv_two_sigma_sq(float noise) const noexcept;
  // log b_N: the flat emission of a frame at pause_distance_per_dim + pause_noise_factor *
  // max(0, noise - pause_noise_allowance) per dimension. noise:
  // SensorNoiseEstimator::variance_per_dim(); weighed with inv_two_sigma_sq(noise).
  float log_pause_emission(float noise) const noexcept;
  // That level as a squared distance over all D dimensions: a template state further than this
  // from the input emits less than the pause state.
  float pause_distance_sq(float noise) const noexcept;
  // Squared distance (over all D dimensions) beyond which no template frame explains the input:
  // the larger of lost_residual_per_dim + lost_noise_factor * noise and lost_residual_factor *
  // residual (ExplainedResidual::level()), at most lost_distance_per_dim.
  float lost_distance_sq(float noise, float residual = 0.0f) const noexcept;
  // lost_distance_per_dim over all D dimensions: the fixed ceiling.
  float lost_ceiling_sq() const noexcept;

 private:
  double pause_per_dim(float noise) const noexcept;  // pause_distance_sq / D

  double dims_ = 0.0;
  double sigma_sq_ = 0.0;
  double emission_noise_factor_ = 0.0;
  double emission_noise_allowance_ = 0.0;
  double pause_distance_per_dim_ = 0.0;
  double pause_noise_factor_ = 0.0;
  double pause_noise_allowance_ = 0.0;
  double lost_ceiling_per_dim_ = 0.0;
  double lost_residual_per_dim_ = 0.0;
  double lost_noise_factor_ = 0.0;
  double lost_residual_factor_ = 0.0;
};

}  // namespace duet
