#include "duet/follow/explained_residual.h"

#include <algorithm>
#include <cmath>

namespace duet {

void ExplainedResidual::reset() noexcept {
  run_s_ = 0.0;
  level_ = 0.0;
}

void ExplainedResidual::update(float best_distance_per_dim, bool followed, double dt_s) noexcept {
  if (!followed || !std::isfinite(best_distance_per_dim) || best_distance_per_dim < 0.0f) {
    run_s_ = 0.0;
    return;
  }
  const double dt = dt_s > 0.0 && std::isfinite(dt_s) ? std::min(dt_s, 1.0) : 1.0 / 60.0;
  run_s_ += dt;
  if (run_s_ < kRunS) return;
  // An exponential average from 0, no running mean at first: a few frames of a wave that
  // happened to hold a run set the level to theirs and made the wave look followed.
  const double weight = std::min(1.0, dt / kTimeConstantS);
  const double residual = std::min(best_distance_per_dim, kMaxResidual);
  level_ += weight * (residual - level_);
}

}  // namespace duet
