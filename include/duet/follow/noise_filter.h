// Smooths the posture part of the input features by as much as the sensor's noise asks for
// (issue 11). Each posture dimension is followed by a constant-velocity Kalman filter: the dance
// moves smoothly (white acceleration of spectral density `acceleration_density`), the sensor adds
// white noise of the variance SensorNoiseEstimator measures, less an allowance (what a clean
// sensor's estimate reads on a fast dance). Every dimension shares the same
// model and noise, hence the same covariance: it is propagated once per frame and its gain
// applied to all of them. With no noise the gain is 1 and the input passes unchanged; at 4
// degrees per axis the filter removes most of the noise without the lag of a plain average (a
// steady motion is predicted, not averaged). An input far outside the prediction (a glitch, the
// sensor back after something else) starts it over. Velocity dimensions pass through (the
// emission caps them).
#pragma once

#include <span>
#include <vector>

namespace duet {

class NoiseFilter {
 public:
  NoiseFilter() = default;
  // Frames of num_dims values, filtered over dimensions [0, posture_dims); acceleration_density
  // in (feature units)^2 / s^3, 0 for no filtering at all; noise_allowance: noise variance per
  // dimension that is not filtered; template_fps gives the time of a frame with a bad dt.
  // Allocates.
  NoiseFilter(int num_dims, int posture_dims, double acceleration_density,
              double noise_allowance, double template_fps);

  void reset() noexcept;
  // One input frame (num_dims finite values) dt_s after the previous one, with the sensor's noise
  // variance per posture dimension. Returns the smoothed frame (valid until the next call; the
  // dimensions past posture_dims as given), or `features` itself when the filter is off or sized
  // for another dimension. Allocates nothing.
  std::span<const float> apply(std::span<const float> features, double dt_s,
                               float noise_variance) noexcept;
  // A missing frame dt_s after the previous one: the next frame is predicted over both intervals.
  void miss(double dt_s) noexcept;
  // The weight of the new frame in the last output (1: unfiltered).
  double gain() const noexcept { return gain_; }

 private:
  // Takes the frame as it is, with the velocity unknown.
  void start(std::span<const float> features, double noise_variance) noexcept;

  int dims_ = 0;
  double density_ = 0.0;
  double allowance_ = 0.0;
  double default_dt_s_ = 1.0 / 60.0;
  std::vector<double> position_, velocity_;  // per posture dimension
  std::vector<float> out_;                   // the last smoothed frame, num_dims
  double gap_s_ = 0.0;                       // time of the missing frames since the last one
  double p00_ = 0.0, p01_ = 0.0, p11_ = 0.0;  // the shared covariance of (position, velocity)
  bool started_ = false;
  double gain_ = 1.0;
};

}  // namespace duet
