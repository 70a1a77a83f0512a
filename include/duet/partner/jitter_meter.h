// How much a noisy signal jitters around its own smooth course (issue 11). The second differences
// s_t of white jitter e are anticorrelated: s_t s_t-1 averages -4 var(e), while a smooth motion
// (a steady advance, a turn that speeds up, a pause) gives second differences that are
// positively correlated or none. So -1/4 of the average product of successive second differences
// (over a time constant, at least 0) reads the sensor's jitter and not the dance's motion; the
// variance of s_t alone also counted a real capture's spins as jitter. Used by the response
// playhead (the follower's frame estimate) and the user's heading filter (the facing's yaw), which
// smooth harder the more their input jitters. Allocates nothing.
#pragma once

#include <cmath>

namespace duet {

class JitterMeter {
 public:
  void reset() noexcept {
    samples_ = 0;
    mean_product_ = 0.0;
  }
  // Forgets the last samples (a jump, a restart) but keeps the measured jitter: it is the
  // sensor's.
  void restart() noexcept { samples_ = 0; }
  // One sample `dt_s` after the previous one. A second difference larger than `max_step` is a
  // move (a jump the caller did not flag), not jitter, and is not counted. Non-finite values or
  // times are ignored.
  void add(double value, double dt_s, double time_constant_s, double max_step) noexcept {
    if (!std::isfinite(value)) return;
    if (samples_ >= 2 && dt_s > 0.0 && std::isfinite(dt_s) && time_constant_s > 0.0) {
      const double second = (value - previous_) - (previous_ - before_previous_);
      if (std::abs(second) <= max_step) {
        if (samples_ >= 3) {
          mean_product_ += (1.0 - std::exp(-dt_s / time_constant_s)) *
                           (second * previous_second_ - mean_product_);
        }
        previous_second_ = second;
        if (samples_ < 3) ++samples_;
      } else {
        samples_ = 2;  // a move: the next second difference has no predecessor
      }
    }
    before_previous_ = previous_;
    previous_ = value;
    if (samples_ < 2) ++samples_;
  }
  // The jitter's RMS, in the signal's units.
  double rms() const noexcept {
    return mean_product_ < 0.0 ? std::sqrt(-mean_product_ / 4.0) : 0.0;
  }

 private:
  int samples_ = 0;  // since the last restart, at most 3 counted (3: a second difference is kept)
  double previous_ = 0.0;
  double before_previous_ = 0.0;
  double previous_second_ = 0.0;
  double mean_product_ = 0.0;  // of successive second differences
};

}  // namespace duet
