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
  if (!(jitter_offset_factor >= 0.0) || !std::isfinite(jitter_offset_factor)) {
    return "jitter_offset_factor must be finite and >= 0";
  }
  if (!(max_jitter_offset_frames >= 0.0) || !std::isfinite(max_jitter_offset_frames)) {
    return "max_jitter_offset_frames must be finite and >= 0";
  }
  if (!(jitter_time_constant_s > 0.0) || !std::isfinite(jitter_time_constant_s)) {
    return "jitter_time_constant_s must be finite and > 0";
  }
  if (!(coast_after_lost_s >= 0.0)) return "coast_after_lost_s must be >= 0";
  if (!(blend_beyond_frames >= 0.0)) return "blend_beyond_frames must be >= 0";
  return "";
}

double ResponsePlayhead::advance(double estimate, bool restart, double tempo, double dt_s,
                                 double frame_rate, const PlayheadParams& params) noexcept {
  const double target = estimate;
  const bool timed =
      dt_s > 0.0 && std::isfinite(dt_s) && frame_rate > 0.0 && std::isfinite(frame_rate);
  if (!primed_ || restart || !timed) {
    position_ = target;
    primed_ = true;
    jitter_.restart();
    jitter_.add(target, dt_s, params.jitter_time_constant_s, 2.0 * params.max_jitter_offset_frames);
    return position_;
  }
  const double rate = tempo > 0.0 && std::isfinite(tempo) ? tempo : 1.0;
  const double predicted = position_ + rate * dt_s * frame_rate;
  // The estimate's jitter (jitter_meter.h); a second difference beyond twice the widest band is
  // a move (a far correction), not jitter.
  jitter_.add(target, dt_s, params.jitter_time_constant_s, 2.0 * params.max_jitter_offset_frames);
  const double band = std::max(
      params.max_offset_frames,
      std::min(params.jitter_offset_factor * jitter_frames(), params.max_jitter_offset_frames));
  const double half_life = params.max_offset_frames > 0.0
                               ? params.pull_half_life_s * band / params.max_offset_frames
                               : params.pull_half_life_s;
  const double pull = half_life > 0.0 ? 1.0 - std::exp2(-dt_s / half_life) : 1.0;
  position_ = predicted + pull * (target - predicted);
  position_ = std::clamp(position_, target - band, target + band);
  return position_;
}

}  // namespace duet
