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

}  // namespace duet
