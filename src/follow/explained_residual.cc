#include "duet/follow/explained_residual.h"

#include <algorithm>
#include <cmath>

namespace duet {

void ExplainedResidual::reset() noexcept {
  run_s_ = 0.0;
  advance_ = 0.0;
  level_ = 0.0;
}

void ExplainedResidual::update(float best_distance_per_dim, bool followed, int advanced_frames,
                               double dt_s, double frame_rate_hz) noexcept {
  if (!followed || !std::isfinite(best_distance_per_dim) || best_distance_per_dim < 0.0f) {
    run_s_ = 0.0;
    advance_ = 0.0;
    return;
  }
  const double dt = dt_s > 0.0 && std::isfinite(dt_s) ? std::min(dt_s, 1.0) : 1.0 / 60.0;
  run_s_ += dt;
  // Steps back count against the pace (jitter back and forth is no progress); a move of more
  // than a few times the input's time counts as that much, so that it cannot stand for a run's
  // pace (FollowerHistory passes 0 for a far move the follower did not call a jump).
  const double rate = frame_rate_hz > 0.0 && std::isfinite(frame_rate_hz) ? frame_rate_hz : 60.0;
  constexpr double kMaxAdvance = 3.0;
  const double advance =
      std::clamp(static_cast<double>(advanced_frames) / (dt * rate), -kMaxAdvance, kMaxAdvance);
  advance_ += std::min(1.0, dt / kAdvanceTimeConstantS) * (advance - advance_);
  if (run_s_ < kRunS || advance_ < kMinAdvance) return;
  // An exponential average from 0, no running mean at first: a few frames of a wave that
  // happened to hold a run set the level to theirs and made the wave look followed.
  const double weight = std::min(1.0, dt / kTimeConstantS);
  const double residual = std::min(best_distance_per_dim, kMaxResidual);
  level_ += weight * (residual - level_);
}

}  // namespace duet
