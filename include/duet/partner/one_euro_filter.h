// The 1-euro filter (Casiez, Roussel and Vogel, CHI 2012) for a 3-vector: an exponential
// low-pass whose cutoff rises with the signal's speed, so a still signal is smoothed hard (sensor
// jitter removed) and a moving one follows with little lag. Used on the user's pose before the
// partner is placed and its hands are aimed (method.md 5.1-5.3): a live sensor's root and wrists
// jitter by about a centimetre per frame, which would otherwise move the whole partner.
#pragma once

#include "duet/math/types.h"

namespace duet {

struct OneEuroParams {
  double min_cutoff_hz = 1.0;  // cutoff of a still signal
  double beta = 10.0;          // cutoff increase per unit of speed (Hz per m/s for positions)
  double derivative_cutoff_hz = 1.0;  // low-pass of the speed estimate that sets the cutoff

  // Empty when valid, else which value is wrong.
  const char* validate() const noexcept;
};

class OneEuroFilter3 {
 public:
  void reset() noexcept { primed_ = false; }
  // Filters one sample taken dt_s after the previous one (dt_s <= 0 or non-finite: the sample is
  // taken as it is and the filter restarts from it). Non-finite samples are not used: the last
  // output is returned.
  Vec3 filter(const Vec3& sample, double dt_s, const OneEuroParams& params) noexcept;
  bool primed() const noexcept { return primed_; }
  // The last output.
  const Vec3& value() const noexcept { return value_; }
  // Moves the state by a rigid motion (value -> rotation * value + translation, its speed
  // rotated), so that a signal expressed in a frame that just moved continues from where it was.
  void rebase(const Quat& rotation, const Vec3& translation) noexcept;

 private:
  bool primed_ = false;
  Vec3 value_ = Vec3::Zero();
  Vec3 speed_ = Vec3::Zero();
};

}  // namespace duet
