#include "duet/live/partner_place.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace duet {

PartnerPlaceStep PartnerPlace::next(const FollowResult& result, double dt_s,
                                    std::span<const PartnerModel> models,
                                    const PlayheadParams& params) noexcept {
  PartnerPlaceStep step{result.take, result.frame_in_take,
                        std::isfinite(result.frame_offset) ? result.frame_offset : 0.0f, false,
                        false};
  // No estimate (or one outside the library): where the partner was.
  const int takes = static_cast<int>(models.size());
  if (step.take < 0 || step.take >= takes || step.frame < 0 ||
      step.frame >= models[static_cast<std::size_t>(step.take)].frame_count()) {
    step.take = std::max(take_, 0);
    step.frame = frame_;
    step.frame_offset = 0.0;
  }
  const bool timed = std::isfinite(dt_s) && dt_s > 0.0;
  const double tempo = std::isfinite(result.tempo) && result.tempo > 0.0f ? result.tempo : 1.0;
  // Between places (the pause state holding the mass) the estimate is not yet decided either,
  // although the follower does not report it lost (FollowParams::pause_reported_lost). A dancer
  // lost only for standing still (FollowResult::held_still) is where the estimate holds: the
  // partner waits there with them.
  const bool undecided = (result.lost && !result.held_still) || result.in_pause;
  lost_s_ = undecided ? lost_s_ + (timed ? dt_s : 0.0) : 0.0;
  step.coasting = undecided && take_ >= 0 && (coasting_ || lost_s_ >= params.coast_after_lost_s);
  if (step.coasting) {
    step.take = take_;
    if (!coasting_) coast_frame_ = frame_;
    const PartnerModel& model = models[static_cast<std::size_t>(step.take)];
    if (timed) coast_frame_ += tempo * dt_s * model.frame_rate();
    coast_frame_ = std::clamp(coast_frame_, 0.0, static_cast<double>(model.frame_count() - 1));
    step.frame = static_cast<int>(std::lround(coast_frame_));
    step.frame_offset = 0.0;
  }
  coasting_ = step.coasting;
  // A jump for the partner: one the follower reports, another take, or a move further than
  // blend_beyond_frames from where the dancer's tempo takes the partner that the follower does
  // not call a jump (while lost or when found again, between look-alike places, while the first
  // placement settles: JumpGate; and the follower's catch-ups of up to 2n + 6 frames, which
  // played in one frame spun the partner's hips at up to 54 rad/s: docs/evaluation.md, "Catch-ups
  // are blended").
  const double frame_rate = models[static_cast<std::size_t>(step.take)].frame_rate();
  const double expected = timed ? tempo * dt_s * frame_rate : tempo * std::max(result.steps, 1);
  const bool far = std::abs(step.frame - frame_ - expected) > params.blend_beyond_frames;
  step.jumped = !step.coasting && (result.jumped || (take_ >= 0 && (step.take != take_ || far)));
  take_ = step.take;
  frame_ = step.frame;
  return step;
}

}  // namespace duet
