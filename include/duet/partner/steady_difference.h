// What a noisy sensor says the user differs from the capture by, held steady (issue 11).
//
// The contact IK aims the partner's hand at the captured hand plus what the user's sensed hand
// differs by from the template's: where it is, and how it is turned. The real difference between
// two bodies varies slowly; under a noisy sensor most of what is sensed of it is noise. A
// SteadyDifference averages the difference over a time that grows with the sensor's measured
// jitter (none on a clean sensor), then trusts the average by the share of its power that is not
// the noise left in it (empirical Bayes, as in James-Stein shrinkage): near 1 on a clean sensor,
// falling towards 0 (the capture as it is) where the noise is as large as the difference it would
// add. The jitter is taken for noise by the share that sets the averaging time, so a clean
// capture's few millimetres of its own motion are neither averaged nor doubted. Allocates nothing.
#pragma once

#include "duet/math/types.h"

namespace duet {

struct SteadyDifferenceParams {
  // The averaging time: time_constant_s * x / (1 + x), x = (jitter / jitter_reference)^4.
  double time_constant_s = 0.1;
  // How long the average's power is measured over; 0: the average is trusted whole.
  double power_time_constant_s = 1.0;
};

class SteadyDifference {
 public:
  void reset() noexcept { *this = SteadyDifference(); }
  // Adds this frame's difference `dt_s` after the previous one; `jitter` is the RMS (over the
  // axes together) of the sensor's white noise in it, `jitter_reference` what the averaging time
  // is scaled by, both in the difference's units. Returns the steady difference. A non-finite
  // difference is skipped (the last steady one is returned).
  Vec3 update(const Vec3& difference, double jitter, double jitter_reference, double dt_s,
              const SteadyDifferenceParams& params) noexcept;
  bool valid() const noexcept { return valid_; }

 private:
  double trust(double noise_variance, double alpha, double dt_s, bool first,
               const SteadyDifferenceParams& params) noexcept;

  Vec3 average_ = Vec3::Zero();
  Vec3 steady_ = Vec3::Zero();  // the last value returned
  bool valid_ = false;
  double seen_s_ = 0.0;  // time averaged so far
  double power_ = 0.0;   // the average's mean square over power_time_constant_s
};

}  // namespace duet
