// Calibrated confidence (issue 11): FollowResult::confidence is the probability that the estimate
// is within 100 ms of the dancer's true place. The HMM's raw measure, the posterior mass within
// the confidence window, says too much under a noisy sensor (a mass of 0.999 was right 93% of the
// time at 4 degrees per axis, 100% on a clean one), so it is mapped through a monotone table per
// band of the sensor's noise (SensorNoiseEstimator), fitted offline by isotonic regression on
// `duet eval` performances other than the reported ones (scripts/fit_confidence_calibration.py;
// docs/follower.md).
#pragma once

namespace duet {

class ConfidenceCalibration {
 public:
  // window_mass in [0, 1] (non-finite counts as 0), noise: the sensor noise variance per posture
  // dimension. Returns a probability in [0, 1]; monotone in window_mass for a fixed noise.
  static float apply(float window_mass, float noise) noexcept;

  // The map's coordinate for a mass: the mass up to 0.9, then its number of nines
  // (-log10(1 - mass), 1 to 6) spread over (0.9, 1]. Same as the fitting script's.
  static float coordinate(float window_mass) noexcept;
};

}  // namespace duet
