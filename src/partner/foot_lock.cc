#include "duet/partner/foot_lock.h"

#include <cmath>

#include "duet/partner/smoothing.h"

namespace duet {
namespace {

Vec3 horizontal(const Vec3& v) { return {v.x(), 0.0, v.z()}; }

}  // namespace

void FootLocker::reset() noexcept { *this = FootLocker(); }

Vec3 FootLocker::update(const std::array<Vec3, 2>& feet_ws, const std::array<bool, 2>& planted,
                        const FootLockParams& params, double dt_s) noexcept {
  Vec3 target = Vec3::Zero();
  int locked_count = 0;
  bool changed = false;
  for (std::size_t i = 0; i < 2; ++i) {
    const Vec3& foot = feet_ws[i];
    if (locked_[i]) {
      const double shift = horizontal(lock_points_[i] - foot).norm();
      if (!planted[i] || !(shift <= params.max_offset_m)) {
        locked_[i] = false;
        changed = true;
      }
    } else if (planted[i] && foot.allFinite() &&
               horizontal(applied_).norm() <= 0.5 * params.max_offset_m) {
      // Lock where the foot is shown now, so locking moves nothing. After a lock hit the limit,
      // new locks wait until the shift has decayed to half of it, so the partner returns to its
      // aligned place instead of staying at the limit.
      locked_[i] = true;
      lock_points_[i] = horizontal(foot + applied_);
      changed = true;
    }
    if (locked_[i]) {
      target += horizontal(lock_points_[i] - foot);
      ++locked_count;
    }
  }
  if (locked_count > 0) target /= locked_count;

  if (changed) {
    // Absorb the jump of the target so the root does not pop; it decays from the next frame on
    // like a critically damped spring (continuous velocity, no kink at the release).
    transition_ = applied_ - target;
  } else {
    decay_spring_damper(transition_, transition_velocity_, params.release_half_life_s, dt_s);
  }
  applied_ = target + transition_;
  if (!applied_.allFinite()) {  // never hand a NaN to the pose
    applied_.setZero();
    transition_.setZero();
    transition_velocity_.setZero();
    locked_ = {false, false};
  }
  return applied_;
}

}  // namespace duet
