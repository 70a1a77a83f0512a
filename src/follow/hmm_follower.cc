#include "duet/follow/hmm_follower.h"

#include <Eigen/Core>
#include <algorithm>
#include <cassert>
#include <cmath>

#include "forward_common.h"

namespace duet {

// ---------------------------------------------------------------------------------------------
// ForwardContext

void ForwardContext::resize(int num_states, int num_dims) {
  assert(num_states > 0);
  num_states_ = num_states;
  const auto size = static_cast<std::size_t>(num_states);
  alpha_.assign(size + 1, 0.0f);
  scratch_.assign(size + 1, 0.0f);
  distance_sq_.assign(size, 0.0f);
  carried_.assign(static_cast<std::size_t>(std::max(num_dims, 0)), 0.0f);
  reset();
}

void ForwardContext::reset() noexcept {
  if (num_states_ == 0) return;
  std::fill(alpha_.begin(), alpha_.end() - 1, 1.0f / static_cast<float>(num_states_));
  alpha_.back() = 0.0f;
  carry_from_ = -1;
  carry_ahead_ = 0.0;
  history_.reset();
}

// ---------------------------------------------------------------------------------------------
// HmmForward: set-up

Result<HmmForward> HmmForward::create(const TemplateModel& model, const FollowParams& params) {
  if (Status status = params.validate(model.num_states()); !status.ok()) return status.error();

  HmmForward forward;
  forward.model_ = &model;
  forward.params_ = params;
  const bool jump = params.jump_enabled;
  // Rows out of a template state sum to 1 (eq. 4-5); the paper's numbers do not (0.825), so
  // the four probabilities are normalised together.
  const float total =
      params.self_prob + params.next_prob + params.skip_prob + (jump ? params.leave_prob : 0.0f);
  forward.band_ = {params.self_prob / total, params.next_prob / total, params.skip_prob / total};
  forward.tempo_limits_ = params.tempo_limits(model.frame_rate_hz());
  forward.leave_ = jump ? params.leave_prob / total : 0.0f;
  forward.pause_stay_ = jump ? params.pause_stay_prob : 1.0f;
  if (jump && !params.resume_weights.empty()) {
    double sum = 0.0;
    for (const float w : params.resume_weights) sum += w;
    forward.resume_.reserve(params.resume_weights.size());
    for (const float w : params.resume_weights) {
      forward.resume_.push_back(static_cast<float>(w / sum));
    }
  }
  forward.params_.resume_weights.clear();  // kept once, normalised, in resume_

  // The emission scale, the pause level and the lost distance follow the sensor noise estimated
  // each frame.
  forward.noise_levels_ = NoiseScaledLevels(params, model.num_dims());
  return forward;
}

int HmmForward::steps_for(double dt_s) const noexcept {
  return follow_detail::steps_for(dt_s, model_->frame_rate_hz(), params_.max_steps_per_frame);
}

BandProbabilities HmmForward::band_for(float tempo) const noexcept {
  return params_.tempo_adaptive ? tilt_band(band_, tempo) : band_;
}

HmmForward::Row HmmForward::row(int j, const BandProbabilities& band) const noexcept {
  const int end = model_->take_end(model_->take_of(j));
  const int remaining = end - 1 - j;  // frames after j in its take
  Row r{{band.self, remaining >= 1 ? band.next : 0.0f, remaining >= 2 ? band.skip : 0.0f}, leave_};
  if (params_.jump_enabled) {
    // End of a take (library): next/skip lead into the pause state, not into the next take.
    r.leave += (band.next - r.band[1]) + (band.skip - r.band[2]);
  } else {
    // No pause state: renormalise what is left; a state with nothing left keeps its mass.
    const float sum = r.band[0] + r.band[1] + r.band[2];
    if (sum > 0.0f) {
      for (float& p : r.band) p /= sum;
    } else {
      r.band[0] = 1.0f;
    }
  }
  return r;
}

float HmmForward::resume(int i) const noexcept {
  if (!params_.jump_enabled) return 0.0f;
  const float r = resume_.empty() ? 1.0f / static_cast<float>(model_->num_states())
                                  : resume_[static_cast<std::size_t>(i)];
  return (1.0f - pause_stay_) * r;
}

// ---------------------------------------------------------------------------------------------
// HmmForward: per frame

namespace {

// The bracket of eq. 11 for the targets i in [begin, end) of one take whose three band sources
// i-2..i are interior rows: self * alpha(i) + next * alpha(i-1) + skip * alpha(i-2) + P_t R_i.
// A plain loop over contiguous floats that the compiler vectorises.
template <bool kUniformResume>
void band_interior(const float* alpha, float* next, int begin, int end, float self, float step,
                   float skip, float pause_out, const float* resume) noexcept {
  for (int i = begin; i < end; ++i) {
    const float from_pause = kUniformResume ? pause_out : pause_out * resume[i];
    next[i] = self * alpha[i] + step * alpha[i - 1] + skip * alpha[i - 2] + from_pause;
  }
}

}  // namespace

void HmmForward::transition(const float* alpha, const BandProbabilities& band,
                            float* next) const noexcept {
  const TemplateModel& model = *model_;
  const int num_states = model.num_states();
  const bool jump = params_.jump_enabled;
  const float pause_mass = alpha[num_states];

  // P_t (eq. 11): the mass resuming from the pause state, independent of i, so computed once.
  // Uniform R_i folds 1/M into it.
  const bool uniform = resume_.empty();
  const float resume_total = jump ? (1.0f - pause_stay_) * pause_mass : 0.0f;
  const float pause_out = uniform ? resume_total / static_cast<float>(num_states) : resume_total;
  const float* resume = uniform ? nullptr : resume_.data();

  // Into the pause state: sum_j alpha(j) L_j + A_NN alpha(N) (eq. 5-6). L_j is leave_ inside a
  // take; the ends of takes add the band mass that has nowhere to go (below).
  const float template_mass = Eigen::Map<const Eigen::ArrayXf>(alpha, num_states).sum();
  float into_pause = jump ? leave_ * template_mass + pause_stay_ * pause_mass : 0.0f;

  for (int take = 0; take < model.num_takes(); ++take) {
    const int begin = model.take_begin(take);
    const int end = model.take_end(take);
    if (uniform) {
      band_interior<true>(alpha, next, begin + 2, end, band.self, band.next, band.skip, pause_out,
                          resume);
    } else {
      band_interior<false>(alpha, next, begin + 2, end, band.self, band.next, band.skip, pause_out,
                           resume);
    }
    // The first two targets have fewer sources; the last two have sources whose rows are cut by
    // the end of the take. Recompute those with the exact rows (O(takes) per frame).
    const int edges[4] = {begin, begin + 1, end - 2, end - 1};
    for (const int i : edges) {
      if (i < begin || i >= end) continue;
      float value = uniform ? pause_out : pause_out * resume[i];
      for (int d = 0; d <= 2 && i - d >= begin; ++d)
        value += alpha[i - d] * row(i - d, band).band[d];
      next[i] = value;
    }
    if (jump) {
      into_pause += alpha[end - 1] * (band.next + band.skip);
      if (end - 2 >= begin) into_pause += alpha[end - 2] * band.skip;
    }
  }
  next[num_states] = into_pause;
}

follow_detail::EmissionDistance HmmForward::emit_all_states(
    const float* phi, float noise, const FollowerHistory& history, std::vector<float>& alpha,
    std::vector<float>& scratch, float* distance_sq, FollowResult& result) const noexcept {
  const int num_states = model_->num_states();
  const follow_detail::EmissionDistance bests = follow_detail::emission_distances(
      *model_, phi, follow_detail::emission_caps(params_), distance_sq);
  const float best = bests.bounded;
  const double log_likelihood = follow_detail::weigh_and_normalise(
      alpha.data(), distance_sq, best, noise_levels_.inv_two_sigma_sq(noise), num_states,
      noise_levels_.log_pause_emission(noise), params_.jump_enabled, scratch.data());
  result.outlier = history.is_outlier(params_, scratch[static_cast<std::size_t>(num_states)] > 0.5f,
                                      best, noise_levels_.pause_distance_sq(noise));
  if (result.outlier) {
    // Set aside like a dropped frame's evidence: the transitions conserve mass.
    follow_detail::normalise(alpha.data(), num_states + 1, num_states);
  } else {
    result.log_likelihood = log_likelihood;
    alpha.swap(scratch);
  }
  // How far the input is from the library counts every limb (FollowResult).
  result.best_distance_per_dim = bests.plain / static_cast<float>(model_->num_dims());
  result.lost = bests.plain > noise_levels_.lost_ceiling_sq();
  return bests;
}

FollowResult HmmForward::step(std::span<const float> features, double dt_s,
                              ForwardContext& context) const noexcept {
  const follow_detail::ScopedFlushDenormals flush_denormals;
  const TemplateModel& model = *model_;
  const int num_states = model.num_states();
  FollowResult result;
  assert(context.num_states_ == num_states && "context sized for another model");
  if (context.num_states_ != num_states) return result;
  assert(features.size() == static_cast<std::size_t>(model.num_dims()));

  result.steps = steps_for(dt_s);
  const bool sized = features.size() == static_cast<std::size_t>(model.num_dims());
  const bool observed = sized && follow_detail::all_finite(features);
  std::span<const float> evidence = features;
  if (sized && !observed && carry_unobserved(features, result.steps, context)) {
    evidence = context.carried_;
    result.partly_observed = true;
  }
  result.missing = !observed && !result.partly_observed;

  // Input slower than the template (or late): the HMM runs at the template rate, so the band is
  // applied once per elapsed template frame before the emission.
  const BandProbabilities band = band_for(context.history_.tempo.tempo());
  for (int s = 0; s < result.steps; ++s) {
    transition(context.alpha_.data(), band, context.scratch_.data());
    context.alpha_.swap(context.scratch_);
  }

  // The noise is read from observed frames only: carried values have none.
  context.history_.sensor_noise.update(features, dt_s, observed);
  result.sensor_noise_per_dim = context.history_.sensor_noise.variance_per_dim();
  const float noise = result.sensor_noise_per_dim;
  const float* phi = nullptr;  // the filtered features, while the frame has them
  float best_plain = 0.0f;
  if (!result.missing) {
    phi = context.history_.noise_filter.apply(evidence, dt_s, noise).data();
    best_plain = emit_all_states(phi, noise, context.history_, context.alpha_, context.scratch_,
                                 context.distance_sq_.data(), result)
                     .plain;
  } else {
    context.history_.noise_filter.miss(dt_s);
    // No evidence: the transitions conserve mass; renormalise only to stop float drift.
    follow_detail::normalise(context.alpha_.data(), num_states + 1, num_states);
    result.best_distance_per_dim = -1.0f;
  }

  const float* alpha = context.alpha_.data();
  follow_detail::decide(model, alpha, 1.0f, alpha[num_states], context.history_.previous_state,
                        result.steps, params_.confidence_window_frames, result);
  // Past the noise-scaled lost distance. lost is completed below, once in_pause is known. The
  // band's tempo and the jump gate go on the fixed ceiling: taught only by frames within the
  // noise-scaled level, the tempo lagged on clean input at 1.4x (100% -> 98.8% within 100 ms).
  result.limb_out_of_line = follow_detail::limb_out_of_line(model, params_, phi, result.state);
  const bool unexplained =
      phi != nullptr &&
      follow_detail::lost_test_distance(model, params_, phi, best_plain, result.state) >
          noise_levels_.lost_distance_sq(noise, context.history_.explained_residual.level());
  context.history_.jump_gate.apply(model, params_, alpha, 1.0f, context.history_.previous_state,
                                   context.history_.previous_lost, result, unexplained);
  context.history_.finish_step(model, params_, tempo_limits_, unexplained, dt_s, result);
  note_carry_anchor(observed, result, context);
  return result;
}

namespace {
// A stall longer than this carries nothing: a place moved on at the tempo for longer drifts from
// the dance (the `stalls` case holds a controller for up to 2 s; FollowParams::missing_lost_s
// calls a frame without evidence lost after 3 s).
constexpr double kMaxCarryS = 3.0;
}  // namespace

bool HmmForward::carry_unobserved(std::span<const float> features, int steps,
                                  ForwardContext& context) const noexcept {
  const TemplateModel& model = *model_;
  const int from = context.carry_from_;
  const double ahead = context.carry_ahead_ + steps * static_cast<double>(context.tempo());
  if (from < 0 || from >= model.num_states() || ahead > kMaxCarryS * model.frame_rate_hz() ||
      context.carried_.size() != features.size()) {
    return false;
  }
  const int take = model.take_of(from);
  const int expected = std::clamp(from + static_cast<int>(std::lround(ahead)),
                                  model.take_begin(take), model.take_end(take) - 1);
  const auto row = model.features().row(expected);
  // NaN is unobserved; an infinity is a broken frame, no evidence at all.
  bool any_observed = false;
  for (std::size_t d = 0; d < features.size(); ++d) {
    if (std::isinf(features[d])) return false;
    const bool seen = !std::isnan(features[d]);
    any_observed = any_observed || seen;
    context.carried_[d] = seen ? features[d] : row(static_cast<Eigen::Index>(d));
  }
  return any_observed;
}

void HmmForward::note_carry_anchor(bool observed, const FollowResult& result,
                                   ForwardContext& context) const noexcept {
  const bool followed = !result.missing && !result.lost && !result.in_pause && !result.outlier;
  if (observed) {
    context.carry_from_ = followed ? result.state : -1;
    context.carry_ahead_ = 0.0;
    return;
  }
  if (context.carry_from_ < 0) return;
  context.carry_ahead_ += result.steps * static_cast<double>(context.tempo());
  // A partly observed frame followed close to where the carry expected it moves the carry on
  // with it (a dancer's tempo drifts while a controller is unseen); a far move does not.
  constexpr double kNearFrames = 6.0;
  const int from = context.carry_from_;
  if (followed && model_->take_of(result.state) == model_->take_of(from) &&
      std::abs(result.state - (from + context.carry_ahead_)) <= kNearFrames) {
    context.carry_from_ = result.state;
    context.carry_ahead_ = 0.0;
  }
}

// ---------------------------------------------------------------------------------------------
// HmmFollower

Result<HmmFollower> HmmFollower::create(const TemplateModel& model, const FollowParams& params) {
  Result<HmmForward> forward = HmmForward::create(model, params);
  if (!forward.ok()) return forward.error();
  ForwardContext context(model.num_states(), model.num_dims());
  context.history() = FollowerHistory(model, params);
  return HmmFollower(std::move(forward).value(), std::move(context));
}

}  // namespace duet
