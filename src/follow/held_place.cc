#include "duet/follow/held_place.h"

#include <cmath>
#include <cstdlib>

namespace duet {

void HeldPlace::update(int state, bool jumped, double dt_s, int reach_states) noexcept {
  if (state < 0 || jumped || anchor_ < 0 || std::abs(state - anchor_) >= reach_states) {
    anchor_ = state;
    held_s_ = 0.0;
    return;
  }
  if (dt_s > 0.0 && std::isfinite(dt_s)) held_s_ += dt_s;
}

void StillSinceFound::update(int state, bool jumped, int found_again_from,
                             int reach_states) noexcept {
  if (found_again_from >= 0) {
    found_at_ = found_again_from;
    jumped = false;  // the move that found the place again is part of finding it
  }
  if (state < 0 || jumped || (found_at_ >= 0 && std::abs(state - found_at_) >= reach_states)) {
    found_at_ = -1;
  }
}

}  // namespace duet
