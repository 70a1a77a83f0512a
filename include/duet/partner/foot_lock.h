// Foot-skate removal (method.md 5.3, paper 5.3 after Kovar et al.): a foot that is near the
// ground and slow stays planted; the correction shifts the root horizontally.
//
// Whether a foot is planted is a property of the captured motion, as in Kovar et al.'s
// footplant annotations: the caller says so per frame (PartnerModel::foot_planted: the captured
// partner's toe within `height_margin_m` of its ground height and slower than
// `speed_threshold_mps` at that frame). Deciding it from the live pose instead fails under
// sensor noise: the partner is placed relative to the user's root, whose jitter moves every
// foot faster than any threshold that still tells a step from a plant.
//
// Per foot (the toe joint), per frame, on the pose before the correction:
// - lock when it is planted; the lock point is where the foot is shown (with the current
//   correction), so locking moves nothing;
// - release when it is no longer planted, or when holding it would move the root more than
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
  // A captured foot is planted when both hold (PartnerModel::foot_planted):
  double height_margin_m = 0.03;     // toe above its ground height
  double speed_threshold_mps = 0.3;  // horizontal speed of the toe
  double max_offset_m = 0.15;        // longest root shift a lock may cause
  double release_half_life_s = 0.1;  // decay of the root shift after the locks change
};

class FootLocker {
 public:
  void reset() noexcept;

  // feet_ws: world positions of the left and right foot points (toe joints) in the pose before
  // the correction. planted: per foot, whether the captured motion has that foot planted at this
  // frame. dt_s: time since the previous call (> 0; the release decays over it). Returns the
  // horizontal (y = 0) offset to add to the root translation this frame.
  Vec3 update(const std::array<Vec3, 2>& feet_ws, const std::array<bool, 2>& planted,
              const FootLockParams& params, double dt_s) noexcept;

  bool locked(int foot) const noexcept { return locked_[static_cast<std::size_t>(foot)]; }
  const Vec3& offset() const noexcept { return applied_; }

 private:
  std::array<bool, 2> locked_{false, false};
  std::array<Vec3, 2> lock_points_{Vec3::Zero(), Vec3::Zero()};
  Vec3 applied_ = Vec3::Zero();     // offset applied last frame
  Vec3 transition_ = Vec3::Zero();  // decaying part of it
  Vec3 transition_velocity_ = Vec3::Zero();
};

}  // namespace duet
