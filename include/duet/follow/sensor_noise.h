// The input sensor's own noise level, estimated online from the input alone (issue 11).
//
// A sensor's white noise makes consecutive frames disagree with a smooth path: the residual of
// linear extrapolation, x2 - x1 - (x1 - x0) * dt2 / dt1, has variance s^2 (1 + (1 + r)^2 + r^2)
// with r = dt2 / dt1 for white noise of variance s^2 per dimension, while a smooth motion leaves
// only its acceleration times dt^2. Averaged over the posture dimensions of the standardised
// features and over time, it measures the noise per dimension that every template distance
// carries on top of the dance's own mismatch, whatever part of the library the input matches (or
// none): a walk captured cleanly stays at a clean level, a noisy dance rises with its noise. The
// follower scales its lost decision and its pause level with it (FollowParams).
#pragma once

#include <span>
#include <vector>

namespace duet {

class SensorNoiseEstimator {
 public:
  SensorNoiseEstimator() = default;
  // Estimates over dimensions [0, posture_dims) of each frame; time_constant_s of the running
  // average in seconds of input; template_fps gives the time of a frame with a bad dt. Allocates.
  SensorNoiseEstimator(int posture_dims, double time_constant_s, double template_fps);

  void reset() noexcept;
  // One input frame (at least posture_dims finite values) dt_s after the previous one. A missing
  // frame (`present` false) breaks the chain: the next three frames start it again.
  void update(std::span<const float> features, double dt_s, bool present) noexcept;

  // White-noise variance per posture dimension (standardised units squared); 0 until three
  // frames in a row have been seen.
  float variance_per_dim() const noexcept { return static_cast<float>(variance_); }

 private:
  int dims_ = 0;
  double time_constant_s_ = 1.0;
  double default_dt_s_ = 1.0 / 60.0;
  std::vector<float> previous_, before_;  // x1, x0
  double previous_dt_s_ = 0.0;            // t1 - t0
  int chain_ = 0;                         // consecutive frames held (0, 1, 2)
  double variance_ = 0.0;
  double seen_s_ = 0.0;  // seconds averaged since reset (a plain mean until the time constant)
};

}  // namespace duet
