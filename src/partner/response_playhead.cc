#include "duet/partner/response_playhead.h"

#include <algorithm>
#include <cmath>

namespace duet {

const char* PlayheadParams::validate() const noexcept {
  if (!(pull_half_life_s >= 0.0) || !std::isfinite(pull_half_life_s)) {
    return "pull_half_life_s must be finite and >= 0";
  }
  if (!(max_offset_frames >= 0.0) || !std::isfinite(max_offset_frames)) {
    return "max_offset_frames must be finite and >= 0";
  }
  return "";
}

double ResponsePlayhead::advance(int estimate, bool restart, double tempo, double dt_s,
                                 double frame_rate, const PlayheadParams& params) noexcept {
  const double target = estimate;
  const bool timed =
      dt_s > 0.0 && std::isfinite(dt_s) && frame_rate > 0.0 && std::isfinite(frame_rate);
  if (!primed_ || restart || !timed) {
    position_ = target;
    primed_ = true;
    return position_;
  }
  const double rate = tempo > 0.0 && std::isfinite(tempo) ? tempo : 1.0;
  const double predicted = position_ + rate * dt_s * frame_rate;
  const double pull =
      params.pull_half_life_s > 0.0 ? 1.0 - std::exp2(-dt_s / params.pull_half_life_s) : 1.0;
  position_ = predicted + pull * (target - predicted);
  position_ =
      std::clamp(position_, target - params.max_offset_frames, target + params.max_offset_frames);
  return position_;
}

}  // namespace duet
