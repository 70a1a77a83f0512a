// Foot-skate removal (method.md 5.3, paper 5.3 after Kovar et al.): a foot that is near the
// ground and slow stays planted; the correction shifts the root horizontally.
//
// Per foot (the toe joint), per frame, on the pose before the correction:
// - lock when its height is within `height_margin_m` of its ground height and its horizontal
//   speed is at most `speed_threshold_mps`; the lock point is where the foot is shown (with the
//   current correction);
// - release when either condition fails, or when holding it would move the root more than
//   `max_offset_m` from where the pose puts it (the partner must still follow the user); no new
//   lock starts while the shift is above half that limit;
// - the root offset that keeps the locked feet on their lock points (the mean over locked feet)
//   is applied horizontally. Whenever the set of locked feet changes, the jump in that target is
//   absorbed by a transition offset that decays like a critically damped spring with
//   `release_half_life_s`, so the root never pops, also when a lock is released.
#pragma once

#include <array>

#include "duet/math/types.h"

namespace duet {

struct FootLockParams {
  // Defaults chosen on the CMU salsa pair 60_01 / 61_01 at 60 Hz, see docs/partner.md.
  double height_margin_m = 0.03;     // toe above its ground height
  double speed_threshold_mps = 0.2;  // horizontal speed of the toe
  double max_offset_m = 0.15;        // longest root shift a lock may cause
  double release_half_life_s = 0.1;  // decay of the root shift after the locks change
};

class FootLocker {
 public:
  void reset() noexcept;

  // feet_ws: world positions of the left and right foot points (toe joints) in the pose before
  // the correction. ground_heights: per foot, the height of that point when it stands on the
  // floor. dt_s: time since the previous call (> 0). Returns the horizontal (y = 0) offset to add
  // to the root translation this frame. The first call after reset() never locks (no speed yet).
  Vec3 update(const std::array<Vec3, 2>& feet_ws, const std::array<double, 2>& ground_heights,
              const FootLockParams& params, double dt_s) noexcept;

  bool locked(int foot) const noexcept { return locked_[static_cast<std::size_t>(foot)]; }
  const Vec3& offset() const noexcept { return applied_; }

 private:
  bool primed_ = false;
  std::array<Vec3, 2> previous_feet_{Vec3::Zero(), Vec3::Zero()};
  std::array<bool, 2> locked_{false, false};
  std::array<Vec3, 2> lock_points_{Vec3::Zero(), Vec3::Zero()};
  Vec3 applied_ = Vec3::Zero();     // offset applied last frame
  Vec3 transition_ = Vec3::Zero();  // decaying part of it
  Vec3 transition_velocity_ = Vec3::Zero();
};

}  // namespace duet
