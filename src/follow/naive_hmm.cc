#include "duet/follow/naive_hmm.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "forward_common.h"

namespace duet {

Result<NaiveHmmFollower> NaiveHmmFollower::create(const TemplateModel& model,
                                                  const FollowParams& params) {
  const int num_states = model.num_states();
  if (num_states > kMaxStates) {
    return make_error("naive HMM", 0,
                      "the dense transition matrix is limited to " + std::to_string(kMaxStates) +
                          " states, the template has " + std::to_string(num_states));
  }
  if (Status status = params.validate(num_states); !status.ok()) return status.error();

  NaiveHmmFollower follower;
  follower.model_ = &model;
  follower.params_ = params;
  const bool jump = params.jump_enabled;
  const int pause = num_states;  // N = M + 1 in the paper's 1-based numbering

  // Written out from eq. 4-6 pair by pair, independently of HmmForward's factorised step, so
  // that the tests comparing the two check the factorisation of eq. 11.
  const float total =
      params.self_prob + params.next_prob + params.skip_prob + (jump ? params.leave_prob : 0.0f);
  follower.band_ = {params.self_prob / total, params.next_prob / total, params.skip_prob / total};
  follower.leave_ = jump ? params.leave_prob / total : 0.0f;
  follower.tempo_limits_ = params.tempo_limits(model.frame_rate_hz());
  double resume_sum = 0.0;
  for (const float w : params.resume_weights) resume_sum += w;

  auto& a = follower.transition_to_from_;
  a.setZero(num_states + 1, num_states + 1);
  // Out of the pause state (eq. 6): stay A_NN, resume (1 - A_NN) R_i.
  a(pause, pause) = jump ? params.pause_stay_prob : 1.0f;
  for (int i = 0; jump && i < num_states; ++i) {
    const float r = params.resume_weights.empty()
                        ? 1.0f / static_cast<float>(num_states)
                        : static_cast<float>(params.resume_weights[i] / resume_sum);
    a(i, pause) = (1.0f - params.pause_stay_prob) * r;
  }
  follower.set_template_columns(follower.band_);

  const double dims = model.num_dims();
  const double sigma = params.emission_sigma;
  const double inv_two_sigma_sq = 1.0 / (2.0 * sigma * sigma);
  follower.inv_two_sigma_sq_ = static_cast<float>(inv_two_sigma_sq);
  follower.log_pause_emission_ =
      static_cast<float>(std::max(-params.pause_distance_per_dim * dims * inv_two_sigma_sq,
                                  double{follow_detail::kMinLogEmission}));
  follower.lost_distance_sq_ = static_cast<float>(params.lost_distance_per_dim * dims);
  const auto size = static_cast<std::size_t>(num_states);
  follower.alpha_.assign(size + 1, 0.0f);
  follower.scratch_.assign(size + 1, 0.0f);
  follower.distance_sq_.assign(size, 0.0f);
  follower.reset();
  return follower;
}

void NaiveHmmFollower::set_template_columns(const BandProbabilities& band) noexcept {
  const TemplateModel& model = *model_;
  const int num_states = model.num_states();
  const int pause = num_states;
  const bool jump = params_.jump_enabled;
  auto& a = transition_to_from_;
  // Out of template state j (eq. 4-5): only these four entries of column j can be non-zero.
  for (int j = 0; j < num_states; ++j) {
    const int end = model.take_end(model.take_of(j));
    a(j, j) = band.self;
    if (j + 1 < end) a(j + 1, j) = band.next;
    if (j + 2 < end) a(j + 2, j) = band.skip;
    // L_j; at the end of a take, next/skip lead into the pause state.
    a(pause, j) =
        jump ? leave_ + (j + 1 >= end ? band.next : 0.0f) + (j + 2 >= end ? band.skip : 0.0f)
             : 0.0f;
    if (!jump) {
      // Left-to-right: renormalise what stays in the take; nothing left -> keep the mass.
      const float sum =
          a(j, j) + (j + 1 < end ? a(j + 1, j) : 0.0f) + (j + 2 < end ? a(j + 2, j) : 0.0f);
      if (sum > 0.0f) {
        a(j, j) /= sum;
        if (j + 1 < end) a(j + 1, j) /= sum;
        if (j + 2 < end) a(j + 2, j) /= sum;
      } else {
        a(j, j) = 1.0f;
      }
    }
  }
}

void NaiveHmmFollower::reset() noexcept {
  const int num_states = model_->num_states();
  std::fill(alpha_.begin(), alpha_.end() - 1, 1.0f / static_cast<float>(num_states));
  alpha_.back() = 0.0f;
  previous_state_ = -1;
  previous_lost_ = false;
  ceiling_lost_.reset();
  tempo_.reset();
  jump_gate_.reset();
}

FollowResult NaiveHmmFollower::step(std::span<const float> features, double dt_s) noexcept {
  const follow_detail::ScopedFlushDenormals flush_denormals;
  const TemplateModel& model = *model_;
  const int num_states = model.num_states();
  FollowResult result;
  assert(features.size() == static_cast<std::size_t>(model.num_dims()));
  result.missing = features.size() != static_cast<std::size_t>(model.num_dims()) ||
                   !follow_detail::all_finite(features);
  result.steps = follow_detail::steps_for(dt_s, model.frame_rate_hz(), params_.max_steps_per_frame);

  if (params_.tempo_adaptive) set_template_columns(tilt_band(band_, tempo_.tempo()));
  const Eigen::Index size = num_states + 1;
  for (int s = 0; s < result.steps; ++s) {
    // eq. 10's sum over every pair (j, i): O(M^2).
    Eigen::Map<Eigen::VectorXf>(scratch_.data(), size).noalias() =
        transition_to_from_ * Eigen::Map<const Eigen::VectorXf>(alpha_.data(), size);
    alpha_.swap(scratch_);
  }

  if (!result.missing) {
    const follow_detail::EmissionDistance bests = follow_detail::emission_distances(
        model, features.data(), follow_detail::emission_caps(params_), distance_sq_.data());
    const float best = bests.bounded;
    result.log_likelihood = follow_detail::weigh_and_normalise(
        alpha_.data(), distance_sq_.data(), best, inv_two_sigma_sq_, num_states,
        log_pause_emission_, params_.jump_enabled, scratch_.data());
    alpha_.swap(scratch_);
    result.best_distance_per_dim = bests.plain / static_cast<float>(model.num_dims());
    result.lost = bests.plain > lost_distance_sq_;  // lost counts every limb, as in the HMM
  } else {
    follow_detail::normalise(alpha_.data(), num_states + 1, num_states);
    result.best_distance_per_dim = -1.0f;
  }

  follow_detail::decide(model, alpha_.data(), 1.0f, alpha_[static_cast<std::size_t>(num_states)],
                        previous_state_, result.steps, params_.confidence_window_frames, result);
  jump_gate_.apply(model, params_, alpha_.data(), 1.0f, previous_state_, previous_lost_, result);
  const bool past_ceiling = result.lost;
  result.lost = result.missing ? previous_lost_ : (result.lost || result.in_pause);
  if (params_.tempo_adaptive) {
    const bool band_move = !result.missing && !result.lost && !result.jumped;
    tempo_.update(previous_state_, result.state, result.steps, dt_s, band_move, tempo_limits_);
  }
  tempo_.observe_rate(result.steps, dt_s, model.frame_rate_hz(), tempo_limits_);
  if (params_.tempo_adaptive) tempo_.start_at_template_tempo(tempo_limits_);
  result.tempo = tempo_.dancer_tempo();
  previous_state_ = result.state;
  previous_lost_ = result.lost;
  // Reported as the exact step does (FollowerHistory::report_lost; no hysteresis at fixed levels).
  result.lost = ceiling_lost_.report(params_, result.lost, past_ceiling, result.missing);
  return result;
}

}  // namespace duet
