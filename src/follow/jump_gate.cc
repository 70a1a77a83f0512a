#include "duet/follow/jump_gate.h"

#include <algorithm>
#include <cmath>

#include "forward_common.h"

namespace duet {

float JumpGate::hold_s(const FollowParams& params, float sensor_noise_per_dim,
                       float best_distance_per_dim, double followed_s) noexcept {
  const float level = params.noisy_jump_hold_level;
  const bool noise_known = std::isfinite(sensor_noise_per_dim);
  const float ramp =
      noise_known ? std::clamp((sensor_noise_per_dim - 0.5f * level) / (0.5f * level), 0.0f, 1.0f)
                  : 0.0f;
  const float hold = std::max(params.jump_hold_s, ramp * params.noisy_jump_hold_s);
  // A far place the input fits poorly: a held limb fitting another pose for a moment, or a
  // look-alike taking the maximum from a place followed for a while. A place just landed on is
  // still being refined: moves from it are taken at once.
  const float fits_up_to =
      std::max(params.unexplained_jump_ratio * (noise_known ? sensor_noise_per_dim : 0.0f),
               params.lost_residual_per_dim);
  const bool established = followed_s + 1e-6 >= params.unexplained_jump_hold_after_s;
  return best_distance_per_dim > fits_up_to && established
             ? std::max(hold, params.unexplained_jump_hold_s)
             : hold;
}

bool JumpGate::looks_alike(const TemplateModel& model, const FollowParams& params, int from,
                           int to) noexcept {
  if (!(params.jump_alike_distance_per_dim > 0.0f) || from < 0 || to < 0) return false;
  const FeatureView rows = model.features();
  const float distance = (rows.row(from) - rows.row(to)).squaredNorm() /
                         static_cast<float>(std::max(model.num_dims(), 1));
  return distance <= params.jump_alike_distance_per_dim;
}

bool JumpGate::through_spell(const TemplateModel& model, const FollowParams& params, bool adrift,
                             int over, FollowResult& result) noexcept {
  const bool unknown = result.missing || result.state < 0;
  // Adrift before any steady frame is a spell too: the maximum wandered from the first frames of
  // a performance that began unexplained (three points' `improv-library`: 17 false jumps in its
  // first 2.6 s), and there is no place to jump from.
  if (adrift) in_spell_ = true;
  if (!in_spell_) return false;
  result.jumped = false;
  if (adrift || unknown) return true;
  // Found again: a jump if out of reach of the place before the spell over the time it lasted
  // (a few frames back from it is jitter, as on any frame).
  result.jumped = settled(params) &&
                  model.is_jump(steady_state_, result.state, over, params.jump_tolerance_frames) &&
                  !looks_alike(model, params, steady_state_, result.state);
  in_spell_ = false;
  forget_candidate();
  return true;
}

void JumpGate::apply(const TemplateModel& model, const FollowParams& params, const float* posterior,
                     float total, int previous_state, bool previous_lost, FollowResult& result,
                     bool unexplained) noexcept {
  const bool adrift =
      !result.missing && result.state >= 0 && (result.lost || result.in_pause || unexplained);
  clock_s_ += static_cast<double>(std::max(result.steps, 1)) / model.frame_rate_hz();
  // The place a jump would leave: the previous frame's, or found again after a spell the one
  // before it, over the spell's steps.
  const int from = in_spell_ ? steady_state_ : previous_state;
  const int over = std::max(result.steps, 1) + (in_spell_ ? steps_since_steady_ : 0);
  if (!through_spell(model, params, adrift, over, result)) {
    decide(model, params, posterior, total, previous_state, previous_lost, result);
  }
  // After a lost frame every move past the band stays a jump (decide): the landing is refined.
  if (result.jumped && !previous_lost && is_catch_up(model, params, from, result.state, over)) {
    result.jumped = false;
  }
  if (result.jumped && !keeps_jump(params)) result.jumped = false;
  if (result.jumped) followed_since_jump_s_ = 0.0;
  if (adrift || result.missing || result.state < 0) {
    steps_since_steady_ += std::max(result.steps, 1);
  } else {
    steady_state_ = result.state;
    steps_since_steady_ = 0;
  }
}

bool JumpGate::is_catch_up(const TemplateModel& model, const FollowParams& params, int from, int to,
                           int steps) noexcept {
  if (!(params.jump_catch_up_s > 0.0f) || from < 0 || to <= from ||
      model.take_of(from) != model.take_of(to)) {
    return false;
  }
  const double past_reach =
      static_cast<double>(to - from - TemplateModel::band_reach(steps)) / model.frame_rate_hz();
  return past_reach <= static_cast<double>(params.jump_catch_up_s) + 1e-9;
}

bool JumpGate::keeps_jump(const FollowParams& params) noexcept {
  if (params.jump_burst_jumps <= 0) return true;
  // Drop the times that fell out of the window (they are kept oldest first).
  int kept = 0;
  for (int i = 0; i < recent_jumps_; ++i) {
    const auto at = static_cast<std::size_t>(i);
    if (clock_s_ - jump_times_[at] <= static_cast<double>(params.jump_burst_s) + 1e-9) {
      jump_times_[static_cast<std::size_t>(kept++)] = jump_times_[at];
    }
  }
  recent_jumps_ = kept;
  if (recent_jumps_ + 1 >= params.jump_burst_jumps) {
    // The place is lost: find it again as at the start, with no jumps on the way.
    recent_jumps_ = 0;
    restart_placement();
    return false;
  }
  jump_times_[static_cast<std::size_t>(recent_jumps_++)] = clock_s_;
  return true;
}

void JumpGate::note_advance(const TemplateModel& model, int from, int to) noexcept {
  // Within reach a move stays in the take (TemplateModel::is_jump: another take is a jump); a
  // spell adrift can end anywhere, and the count starts again there.
  if (advance_origin_ < 0 || model.take_of(advance_origin_) != model.take_of(from)) {
    advance_origin_ = from;
    advance_furthest_ = from;
  }
  advance_furthest_ = std::max(advance_furthest_, to);
  advanced_s_ = static_cast<double>(advance_furthest_ - advance_origin_) / model.frame_rate_hz();
}

void JumpGate::decide(const TemplateModel& model, const FollowParams& params,
                      const float* posterior, float total, int previous_state, bool previous_lost,
                      FollowResult& result) noexcept {
  // Right after a lost frame (a jump's first landing is often one: a poor match on the way in)
  // every move past the band is a jump again: the landing is refined, and the partner must
  // restart at the refined place (else it plays on from the poor one).
  const int tolerance = previous_lost ? 0 : params.jump_tolerance_frames;
  const int steps = std::max(result.steps, 1);
  const double step_s = static_cast<double>(steps) / model.frame_rate_hz();
  followed_since_jump_s_ += step_s;
  if (previous_state < 0 || result.missing || result.state < 0 ||
      !model.is_jump(previous_state, result.state, steps, tolerance)) {
    // Within reach of the old place: no jump, whatever the raw maximum's step was.
    result.jumped = false;
    // Settling counts the frames the follower is sure of; once settled, it stays settled.
    const bool was_settled = settled(params);
    const bool sure = was_settled || result.window_mass >= params.jump_settle_mass;
    if (previous_state >= 0 && result.state >= 0 && sure) {
      settled_s_ += step_s;
      if (!was_settled) note_advance(model, previous_state, result.state);
    }
    forget_candidate();
    return;
  }
  if (!settled(params)) {
    // Still finding the first place: take the new one and start settling there.
    result.jumped = false;
    restart_placement();
    return;
  }
  const float hold = hold_s(params, result.sensor_noise_per_dim, result.best_distance_per_dim,
                            followed_since_jump_s_);
  if (previous_lost || result.in_pause) {
    result.jumped =
        !looks_alike(model, params, previous_state, result.state);  // nothing to hold on to
    forget_candidate();
    return;
  }
  // The maximum is far from the old place. The same far place (moving along its take) holds on;
  // another one starts over.
  const bool same_candidate =
      candidate_state_ >= 0 && !model.is_jump(candidate_state_, result.state, steps, tolerance);
  held_s_ = same_candidate ? held_s_ + step_s : step_s;
  candidate_state_ = result.state;
  // The old place's reach: where its continuation would be.
  const int take = model.take_of(previous_state);
  const int begin = std::max(model.take_begin(take), previous_state - tolerance);
  const int end = std::min(model.take_end(take),
                           previous_state + TemplateModel::band_reach(steps) + tolerance + 1);
  double old_mass = 0.0;
  int best = begin;  // the most likely state there
  for (int i = begin; i < end; ++i) {
    old_mass += posterior[i];
    if (posterior[i] > posterior[best]) best = i;
  }
  if (held_s_ + 1e-6 >= hold &&  // (3 frames of 1/60 s make 0.05 s)
      old_mass <= static_cast<double>(params.jump_old_place_mass) * total) {
    result.jumped = !looks_alike(model, params, previous_state, result.state);
    forget_candidate();
    return;
  }
  // Not yet: report the best state within reach of the old place.
  follow_detail::describe_state(model, posterior, total, best, params.confidence_window_frames,
                                result);
  result.jumped = false;
}

}  // namespace duet
