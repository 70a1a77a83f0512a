#include "duet/follow/beam_follower.h"

#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <string>

#include "forward_common.h"

namespace duet {

using follow_detail::log_emission;

namespace {

// Below this the kept mass has lost too many bits to be normalised (as forward_common.cc).
constexpr double kMinNormaliser = 1e-30;

Error left_to_right_error() {
  return make_error("beam follower", 0,
                    "beam mode needs the jump HMM's pause state; the left-to-right HMM runs "
                    "only with the exact step");
}

}  // namespace

Status BeamParams::validate() const {
  auto fail = [](const std::string& what) { return make_error("beam parameters", 0, what); };
  if (jump_candidates < 1) return fail("jump_candidates must be >= 1");
  if (wide_jump_candidates < jump_candidates) {
    return fail("wide_jump_candidates must be >= jump_candidates");
  }
  if (radius_candidates < wide_jump_candidates) {
    return fail("radius_candidates must be >= wide_jump_candidates");
  }
  if (!(prune_ratio >= 0.0f && prune_ratio < 1.0f)) return fail("prune_ratio must be in [0, 1)");
  if (!(deep_prune_ratio >= 0.0f && deep_prune_ratio < 1.0f)) {
    return fail("deep_prune_ratio must be in [0, 1)");
  }
  if (!(well_fitting_ratio >= 1.0f && std::isfinite(well_fitting_ratio))) {
    return fail("well_fitting_ratio must be finite and >= 1");
  }
  if (well_fitting_states < 0) return fail("well_fitting_states must be >= 0");
  if (max_states < 1) return fail("max_states must be >= 1");
  if (!(outside_mass_tolerance >= 0.0f && std::isfinite(outside_mass_tolerance))) {
    return fail("outside_mass_tolerance must be finite and >= 0");
  }
  if (!(lost_full_step_s >= 0.0 && std::isfinite(lost_full_step_s))) {
    return fail("lost_full_step_s must be finite and >= 0");
  }
  if (!(lost_spell_before_s >= 0.0 && std::isfinite(lost_spell_before_s))) {
    return fail("lost_spell_before_s must be finite and >= 0");
  }
  return Ok{};
}

BeamParams BeamParams::suited_to(const FollowParams& params) {
  BeamParams beam;
  if (!params.tempo_adaptive || params.skip_prob == 0.0f) {
    beam.prune_ratio = std::min(beam.prune_ratio, 1e-20f);
    beam.deep_prune_ratio = std::min(beam.deep_prune_ratio, 1e-20f);
  }
  return beam;
}

// ---------------------------------------------------------------------------------------------
// BeamContext

BeamContext::BeamContext(int num_states, const BeamParams& beam, int max_steps_per_frame) {
  assert(num_states > 0);
  num_states_ = num_states;
  const auto size = static_cast<std::size_t>(num_states);
  alpha_.assign(size + 1, 0.0f);
  scratch_.assign(size + 1, 0.0f);
  distance_sq_.assign(size, 0.0f);
  // Each transition grows a run of the beam by at most 2 states; then come the candidates.
  const std::size_t list =
      std::min(size, static_cast<std::size_t>(beam.max_states) *
                             (1 + 2 * static_cast<std::size_t>(std::max(1, max_steps_per_frame))) +
                         static_cast<std::size_t>(beam.radius_candidates));
  beam_.reserve(list);
  next_.reserve(list);
  weighted_.assign(list, 0.0f);
  candidates_.assign(static_cast<std::size_t>(beam.radius_candidates), 0);
  candidate_d2_.assign(static_cast<std::size_t>(beam.radius_candidates), 0.0f);
  reset();
}

void BeamContext::reset() noexcept {
  if (num_states_ == 0) return;
  std::fill(alpha_.begin(), alpha_.end() - 1, 1.0f / static_cast<float>(num_states_));
  alpha_.back() = 0.0f;
  std::fill(scratch_.begin(), scratch_.end(), 0.0f);
  beam_.clear();
  next_.clear();
  background_ = 0.0f;
  full_next_ = true;
  full_steps_ = 0;
  deferred_steps_ = 0;
  since_full_s_ = 0.0;
  history_.reset();
  frame_noise_ = 0.0f;
}

// ---------------------------------------------------------------------------------------------
// BeamForward

Result<BeamForward> BeamForward::create(const TemplateModel& model, const FollowParams& params,
                                        const BeamParams& beam) {
  if (Status status = beam.validate(); !status.ok()) return status.error();
  if (!params.jump_enabled) return left_to_right_error();
  Result<JumpCandidateIndex> index = JumpCandidateIndex::build(model);
  if (!index) return index.error();
  return create(model, params, beam,
                std::make_shared<const JumpCandidateIndex>(std::move(index).value()));
}

Result<BeamForward> BeamForward::create(const TemplateModel& model, const FollowParams& params,
                                        const BeamParams& beam,
                                        std::shared_ptr<const JumpCandidateIndex> index) {
  if (Status status = beam.validate(); !status.ok()) return status.error();
  if (!params.jump_enabled) return left_to_right_error();
  if (!index) return make_error("beam follower", 0, "no jump candidate index");
  if (index->num_states() != model.num_states()) {
    return make_error("beam follower", 0,
                      "jump candidate index of " + std::to_string(index->num_states()) +
                          " states for a model of " + std::to_string(model.num_states()));
  }
  Result<HmmForward> exact = HmmForward::create(model, params);
  if (!exact) return exact.error();
  BeamForward forward(std::move(exact).value(), std::move(index), beam);
  forward.max_resume_share_ = 1.0f / static_cast<float>(model.num_states());
  for (const float r : forward.exact_.resume_) {
    forward.max_resume_share_ = std::max(forward.max_resume_share_, r);
  }
  return forward;
}

float BeamForward::resume_share(int i) const noexcept {
  return exact_.resume_.empty() ? 1.0f / static_cast<float>(exact_.model_->num_states())
                                : exact_.resume_[static_cast<std::size_t>(i)];
}

void BeamForward::sparse_transition(const BandProbabilities& band,
                                    BeamContext& context) const noexcept {
  const TemplateModel& model = *exact_.model_;
  const int num_states = model.num_states();
  const bool jump = exact_.params_.jump_enabled;
  float* alpha = context.alpha_.data();
  float* next = context.scratch_.data();
  const float pause_mass = alpha[num_states];

  float beam_mass = 0.0f;
  for (const int j : context.beam_) beam_mass += alpha[j];
  float into_pause = 0.0f;
  if (jump) {
    into_pause =
        exact_.leave_ * (beam_mass + context.background_) + exact_.pause_stay_ * pause_mass;
  }
  // The band moves each state's mass to j, j + 1, j + 2 of its take. The beam is sorted, so the
  // targets come in order and a target at or below the last one added is already in next_.
  context.next_.clear();
  for (const int j : context.beam_) {
    const HmmForward::Row r = exact_.row(j, band);
    if (jump) into_pause += alpha[j] * (r.leave - exact_.leave_);  // the end of a take
    const int last = std::min(j + 2, model.take_end(model.take_of(j)) - 1);
    for (int t = j; t <= last; ++t) {
      if (context.next_.empty() || t > context.next_.back()) {
        context.next_.push_back(t);
        next[t] = 0.0f;
      }
      next[t] += alpha[j] * r.band[t - j];
    }
  }
  for (const int j : context.beam_) alpha[j] = 0.0f;
  // The background moves along the band as any uniform mass (its take ends are neglected: it
  // is spread over the whole library) and receives what resumes from the pause state.
  if (jump) {
    context.background_ = context.background_ * (band.self + band.next + band.skip) +
                          (1.0f - exact_.pause_stay_) * pause_mass;
  }
  alpha[num_states] = 0.0f;
  next[num_states] = into_pause;
  context.alpha_.swap(context.scratch_);
  context.beam_.swap(context.next_);
}

BeamForward::CandidateSet BeamForward::nearest_candidates(const float* phi, int k,
                                                          BeamContext& context) const noexcept {
  CandidateSet set;
  set.found =
      index_->nearest(phi, k, context.candidates_.data(), context.candidate_d2_.data(), set.bound);
  set.bounded = set.found == k;
  std::sort(context.candidates_.data(), context.candidates_.data() + set.found);
  return set;
}

BeamForward::CandidateSet BeamForward::candidates_within(const float* phi, float radius_sq,
                                                         BeamContext& context) const noexcept {
  CandidateSet set;
  set.found = index_->within(phi, radius_sq, beam_.radius_candidates, context.candidates_.data(),
                             context.candidate_d2_.data());
  set.bound = radius_sq;
  set.bounded = set.found < exact_.model_->num_states();
  if (set.found > 0) {
    std::sort(context.candidates_.data(), context.candidates_.data() + set.found);
  }
  return set;
}

bool BeamForward::sparse_emission(const float* phi, const CandidateSet& candidates,
                                  BeamContext& context, FollowResult& result, float& settling_bound,
                                  bool must_settle) const noexcept {
  const TemplateModel& model = *exact_.model_;
  const int num_states = model.num_states();
  const FollowParams& params = exact_.params_;
  const float inv_two_sigma_sq = exact_.noise_levels_.inv_two_sigma_sq(context.frame_noise_);
  float* alpha = context.alpha_.data();
  settling_bound = FLT_MAX;

  // The jump candidates, merged into the beam (both sorted) in next_.
  const int found = candidates.found;
  const std::uint32_t* sorted = context.candidates_.data();
  context.next_.clear();
  {
    std::size_t b = 0;
    int c = 0;
    const std::size_t beam_size = context.beam_.size();
    while (b < beam_size || c < found) {
      const int from_beam = b < beam_size ? context.beam_[b] : num_states;
      const int from_index = c < found ? static_cast<int>(sorted[c]) : num_states;
      const int state = std::min(from_beam, from_index);
      context.next_.push_back(state);
      if (from_beam == state) ++b;
      if (from_index == state) ++c;
    }
  }
  const std::size_t count = context.next_.size();

  float best = FLT_MAX;
  float best_plain = FLT_MAX;  // without the limb bound, for lost
  float* d2 = context.distance_sq_.data();
  const follow_detail::DistanceCaps caps = follow_detail::emission_caps(params);
  for (std::size_t k = 0; k < count; ++k) {
    const follow_detail::EmissionDistance distance =
        follow_detail::state_emission_distance(model, phi, context.next_[k], caps);
    d2[k] = distance.bounded;
    best = std::min(best, d2[k]);
    best_plain = std::min(best_plain, distance.plain);
  }
  // The bound the states left out would have to be beyond for this frame's decisions to be the
  // exact step's (0: they are already). Lost is decided on the best plain distance of the whole
  // library; states left out are >= the bound. (The index bounds the plain distance: a state
  // left out whose limb bound takes much off can emit above the bound's emission. The beam is an
  // approximation there.)
  const float bound = candidates.bound;
  float needed = 0.0f;
  const float lost_sq = exact_.noise_levels_.lost_ceiling_sq();
  const float unexplained_sq = exact_.noise_levels_.lost_distance_sq(
      context.frame_noise_, context.history_.explained_residual.level());
  if (candidates.bounded) {
    if (best_plain > lost_sq && bound <= lost_sq) needed = std::max(needed, lost_sq);
    if (best_plain > unexplained_sq && bound <= unexplained_sq) {
      needed = std::max(needed, unexplained_sq);
    }
  }

  const float log_pause = exact_.noise_levels_.log_pause_emission(context.frame_noise_);
  const bool jump = params.jump_enabled;
  const float max_template = log_emission(best, inv_two_sigma_sq);
  const float shift = jump ? std::max(max_template, log_pause) : max_template;
  const float background = context.background_;
  float* weighted = context.weighted_.data();
  double sum = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const int i = context.next_[k];
    const float predicted = alpha[i] + background * resume_share(i);
    weighted[k] = predicted * std::exp(log_emission(d2[k], inv_two_sigma_sq) - shift);
    sum += weighted[k];
  }
  const float pause = jump ? alpha[num_states] * std::exp(log_pause - shift) : 0.0f;
  sum += pause;
  if (!(sum >= kMinNormaliser)) return false;
  // The states left out: their prediction is the background, their emission at most the
  // bound's. Their total is spread over up to M states, so it only matters where it could change
  // a decision: the maximum, the confidence window, the pause state's majority.
  float largest = 0.0f;
  for (std::size_t k = 0; k < count; ++k) largest = std::max(largest, weighted[k]);
  if (candidates.bounded && background > 0.0f) {
    // The smallest bound at which `share` of the background, emitted there, is at most `limit`
    // (background * share * exp(-r / (2 s^2) - shift) <= limit).
    const auto bound_for = [&](double share, double limit) {
      if (!(limit > 0.0)) return FLT_MAX;
      const double r =
          (std::log(static_cast<double>(background) * share / limit) - static_cast<double>(shift)) /
          static_cast<double>(inv_two_sigma_sq);
      return static_cast<float>(std::clamp(r, 0.0, static_cast<double>(FLT_MAX)));
    };
    const double emitted =
        std::exp(static_cast<double>(log_emission(bound, inv_two_sigma_sq) - shift));
    const double outside_total = static_cast<double>(background) * emitted;
    const double outside_state = static_cast<double>(background) * max_resume_share_ * emitted;
    const double window = 2.0 * params.confidence_window_frames + 1.0;
    const bool in_pause = pause > 0.5 * sum;
    if (outside_state >= static_cast<double>(largest)) {
      needed = std::max(needed, bound_for(max_resume_share_, largest));
    }
    if (outside_state * window > beam_.outside_mass_tolerance * sum) {
      needed = std::max(needed,
                        bound_for(max_resume_share_ * window, beam_.outside_mass_tolerance * sum));
    }
    if (in_pause != (pause > 0.5 * (sum + outside_total))) {
      needed = std::max(needed, bound_for(1.0, 2.0 * pause - sum));
    }
  }
  if (needed > 0.0f && must_settle) {
    // A little beyond, so that a search to it settles the frame (the tests above are strict).
    settling_bound = needed < FLT_MAX / 2 ? needed * 1.001f + 1e-6f : FLT_MAX;
    return false;
  }

  // Accepted. An outlier's evidence is set aside, as in the exact step (FollowParams::
  // gate_outliers); the pause state's majority is settled above.
  result.best_distance_per_dim = best_plain / static_cast<float>(model.num_dims());
  result.lost = best_plain > lost_sq;
  if (context.history_.is_outlier(params, pause > 0.5 * sum, best,
                                  exact_.noise_levels_.pause_distance_sq(context.frame_noise_))) {
    renormalise_without_evidence(context);
    result.outlier = true;
    return true;
  }
  // The posterior over the merged states; those below the threshold leave the beam.
  const float scale = static_cast<float>(1.0 / sum);
  const float threshold = prune_threshold(context, {weighted, count}, largest);
  // A few states that fit about as well as the best one keep far less mass (BeamParams::
  // well_fitting_ratio): the exact step keeps every state, and its mass grows there frame by
  // frame once the place followed stops fitting.
  const float fits_sq = best + std::log(beam_.well_fitting_ratio) / inv_two_sigma_sq;
  const float fit_threshold = largest * beam_.deep_prune_ratio;
  int well_fitting = 0;
  context.beam_.clear();
  for (std::size_t k = 0; k < count; ++k) {
    const int i = context.next_[k];
    const bool fits = weighted[k] < threshold && weighted[k] >= fit_threshold && d2[k] <= fits_sq &&
                      well_fitting < beam_.well_fitting_states;
    if (fits) ++well_fitting;
    if ((weighted[k] >= threshold || fits) && weighted[k] > 0.0f) {
      alpha[i] = weighted[k] * scale;
      context.beam_.push_back(i);
    } else {
      alpha[i] = 0.0f;
    }
  }
  alpha[num_states] = pause * scale;
  context.background_ = 0.0f;  // its emitted mass is left out (bounded above)
  if (static_cast<int>(context.beam_.size()) > beam_.max_states) context.full_next_ = true;
  result.log_likelihood = std::log(sum) + static_cast<double>(shift);
  return true;
}

bool BeamForward::sparse_step(const float* phi, BeamContext& context, FollowResult& result,
                              bool accept_unsettled) const noexcept {
  float settling_bound = FLT_MAX;
  if (sparse_emission(phi, nearest_candidates(phi, beam_.jump_candidates, context), context, result,
                      settling_bound)) {
    return true;
  }
  const CandidateSet wide = nearest_candidates(phi, beam_.wide_jump_candidates, context);
  if (sparse_emission(phi, wide, context, result, settling_bound)) return true;
  if (accept_unsettled) {
    return sparse_emission(phi, wide, context, result, settling_bound, false);
  }
  if (settling_bound >= FLT_MAX) return false;
  const CandidateSet within = candidates_within(phi, settling_bound, context);
  return within.found >= 0 && sparse_emission(phi, within, context, result, settling_bound);
}

bool BeamForward::between_full_steps(double dt_s, const BeamContext& context) const noexcept {
  return beam_.lost_full_step_s > 0.0 && context.history_.previous_lost &&
         context.history_.previous_state >= 0 &&
         context.history_.lost_spell_s + 1e-9 >= beam_.lost_spell_before_s &&
         context.since_full_s_ + dt_s < beam_.lost_full_step_s;
}

bool BeamForward::unexplained_nearby(const float* phi, BeamContext& context,
                                     FollowResult& result) const noexcept {
  const TemplateModel& model = *exact_.model_;
  const FollowParams& params = exact_.params_;
  const CandidateSet nearest = nearest_candidates(phi, beam_.jump_candidates, context);
  const float unexplained_sq = exact_.noise_levels_.lost_distance_sq(
      context.frame_noise_, context.history_.explained_residual.level());
  float best_plain = FLT_MAX;
  // The place reported before, then the candidates, measured as the lost test measures.
  for (int k = -1; k < nearest.found; ++k) {
    const int state = k < 0 ? context.history_.previous_state
                            : static_cast<int>(context.candidates_[static_cast<std::size_t>(k)]);
    const float plain = follow_detail::state_emission_distance(model, phi, state,
                                                               follow_detail::emission_caps(params))
                            .plain;
    best_plain = std::min(best_plain, plain);
    if (follow_detail::lost_test_distance(model, params, phi, plain, state) <= unexplained_sq) {
      return false;
    }
  }
  result.best_distance_per_dim = best_plain / static_cast<float>(model.num_dims());
  result.lost = best_plain > exact_.noise_levels_.lost_ceiling_sq();
  return true;
}

void BeamForward::renormalise_without_evidence(BeamContext& context) const noexcept {
  const int num_states = exact_.model_->num_states();
  float* alpha = context.alpha_.data();
  float total = alpha[num_states] + context.background_;
  for (const int i : context.beam_) total += alpha[i];
  if (total > 0.0f && std::isfinite(total)) {
    const float scale = 1.0f / total;
    for (const int i : context.beam_) alpha[i] *= scale;
    alpha[num_states] *= scale;
    context.background_ *= scale;
  }
  // Unpruned, the beam spreads along the band while frames carry no evidence; too wide, the next
  // frame is a full step (which also keeps the buffers within their reserved size).
  if (static_cast<int>(context.beam_.size()) > beam_.max_states) context.full_next_ = true;
}

void BeamForward::materialise(BeamContext& context) const noexcept {
  const int num_states = exact_.model_->num_states();
  const float background = context.background_;
  if (background > 0.0f) {
    float* alpha = context.alpha_.data();
    for (int i = 0; i < num_states; ++i) alpha[i] += background * resume_share(i);
  }
  context.background_ = 0.0f;
}

float BeamForward::prune_threshold(const BeamContext& context, std::span<const float> masses,
                                   float largest) const noexcept {
  const float usual = largest * beam_.prune_ratio;
  if (context.history_.jump_gate.settled(exact_.params_) ||
      !(beam_.deep_prune_ratio < beam_.prune_ratio)) {
    return usual;
  }
  // Deeper, unless that keeps a beam too wide to save anything (a library of look-alikes).
  const float deep = largest * beam_.deep_prune_ratio;
  const int most = beam_.max_states / 2;
  int kept = 0;
  for (const float mass : masses) {
    if (mass >= deep && mass > 0.0f && ++kept > most) return usual;
  }
  return deep;
}

void BeamForward::rebuild_beam(BeamContext& context) const noexcept {
  const int num_states = exact_.model_->num_states();
  float* alpha = context.alpha_.data();
  float largest = 0.0f;
  for (int i = 0; i < num_states; ++i) largest = std::max(largest, alpha[i]);
  const float threshold =
      prune_threshold(context, {alpha, static_cast<std::size_t>(num_states)}, largest);
  context.beam_.clear();
  for (int i = 0; i < num_states; ++i) {
    if (alpha[i] >= threshold && alpha[i] > 0.0f) {
      if (static_cast<int>(context.beam_.size()) == beam_.max_states) {
        context.beam_.clear();
        context.full_next_ = true;  // too wide: stay dense
        return;
      }
      context.beam_.push_back(i);
    }
  }
  // The states left out hold less than prune_ratio of the maximum each: dropped.
  std::size_t k = 0;
  float kept = alpha[num_states];
  for (int i = 0; i < num_states; ++i) {
    if (k < context.beam_.size() && context.beam_[k] == i) {
      kept += alpha[i];
      ++k;
    } else {
      alpha[i] = 0.0f;
    }
  }
  if (kept > 0.0f) {
    const float scale = 1.0f / kept;
    for (const int i : context.beam_) alpha[i] *= scale;
    alpha[num_states] *= scale;
  }
  std::fill(context.scratch_.begin(), context.scratch_.end(), 0.0f);
  context.full_next_ = false;
}

int BeamForward::sparse_argmax(const BeamContext& context) const noexcept {
  // The beam is sorted: the first of equal maxima wins, as in the full argmax.
  int state = context.beam_.empty() ? 0 : context.beam_.front();
  float best = -1.0f;
  for (const int i : context.beam_) {
    if (context.alpha_[static_cast<std::size_t>(i)] > best) {
      best = context.alpha_[static_cast<std::size_t>(i)];
      state = i;
    }
  }
  return state;
}

FollowResult BeamForward::step(std::span<const float> features, double dt_s,
                               BeamContext& context) const noexcept {
  const follow_detail::ScopedFlushDenormals flush_denormals;
  const TemplateModel& model = *exact_.model_;
  const FollowParams& params = exact_.params_;
  const int num_states = model.num_states();
  FollowResult result;
  assert(context.num_states_ == num_states && "context sized for another model");
  if (context.num_states_ != num_states) return result;

  result.missing = features.size() != static_cast<std::size_t>(model.num_dims()) ||
                   !follow_detail::all_finite(features);
  result.steps = exact_.steps_for(dt_s);
  const BandProbabilities band = exact_.band_for(context.history_.tempo.tempo());

  // The sensor's noise and the filtered features (neither depends on the posterior).
  context.history_.sensor_noise.update(features, dt_s, !result.missing);
  result.sensor_noise_per_dim = context.history_.sensor_noise.variance_per_dim();
  context.frame_noise_ = result.sensor_noise_per_dim;
  if (result.missing) context.history_.noise_filter.miss(dt_s);
  const float* phi = nullptr;  // the filtered features, while the frame has them
  if (!result.missing) {
    phi = context.history_.noise_filter.apply(features, dt_s, context.frame_noise_).data();
  }

  // In a spell lost, between full steps (BeamParams::lost_full_step_s): with no beam (the
  // posterior spread wide), a frame that neither the place reported before nor the nearest jump
  // candidates explain weighs no evidence; with a beam, the emission over the beam and the wide
  // candidates finishes the frame although the states left out could change a decision.
  const bool spell = phi != nullptr && between_full_steps(dt_s, context);
  const bool deferred = spell && context.full_next_ && unexplained_nearby(phi, context, result);
  bool dense = context.full_next_ && !deferred;
  if (dense) {
    materialise(context);
    const int steps = context.deferred_steps_ + result.steps;
    for (int s = 0; s < steps; ++s) {
      exact_.transition(context.alpha_.data(), band, context.scratch_.data());
      context.alpha_.swap(context.scratch_);
    }
    context.deferred_steps_ = 0;
  } else if (deferred) {
    context.deferred_steps_ += result.steps;  // the dense posterior waits for the next full step
  } else {
    for (int s = 0; s < result.steps; ++s) sparse_transition(band, context);
  }

  if (deferred) {
    // Lost: decided by unexplained_nearby.
  } else if (!result.missing) {
    // Uncertain with the usual candidates: widen the search; still uncertain, the beam may have
    // lost the dancer: finish the frame with the full step.
    if (!dense && !sparse_step(phi, context, result, spell)) {
      materialise(context);
      dense = true;
    }
    if (dense) {
      exact_.emit_all_states(phi, context.frame_noise_, context.history_, context.alpha_,
                             context.scratch_, context.distance_sq_.data(), result);
    }
  } else if (dense) {
    follow_detail::normalise(context.alpha_.data(), num_states + 1, num_states);
    result.best_distance_per_dim = -1.0f;
  } else {
    renormalise_without_evidence(context);
    result.best_distance_per_dim = -1.0f;
  }

  const float* alpha = context.alpha_.data();
  context.since_full_s_ += dt_s > 0.0 && std::isfinite(dt_s) ? dt_s : 0.0;
  if (deferred) {
    // Lost, at the place reported before (the posterior is the last full step's).
    follow_detail::describe_state(model, alpha, 1.0f, context.history_.previous_state,
                                  params.confidence_window_frames, result);
    result.in_pause = true;
    result.jumped = false;
  } else if (dense) {
    ++context.full_steps_;
    context.since_full_s_ = 0.0;
    follow_detail::decide(model, alpha, 1.0f, alpha[num_states], context.history_.previous_state,
                          result.steps, params.confidence_window_frames, result);
  } else {
    follow_detail::describe_state(model, alpha, 1.0f, sparse_argmax(context),
                                  params.confidence_window_frames, result, context.beam_);
    result.in_pause = alpha[num_states] > 0.5f;
    result.jumped = model.is_jump(context.history_.previous_state, result.state, result.steps);
  }
  result.limb_out_of_line = follow_detail::limb_out_of_line(model, params, phi, result.state);
  const bool unexplained =
      phi != nullptr &&
      follow_detail::lost_test_distance(
          model, params, phi, result.best_distance_per_dim * static_cast<float>(model.num_dims()),
          result.state) >
          exact_.noise_levels_.lost_distance_sq(context.frame_noise_,
                                                context.history_.explained_residual.level());
  context.history_.jump_gate.apply(model, params, alpha, 1.0f, context.history_.previous_state,
                                   context.history_.previous_lost, result, unexplained);
  if (dense && !result.missing) rebuild_beam(context);

  context.history_.finish_step(model, params, exact_.tempo_limits_, unexplained, dt_s, result);
  return result;
}

// ---------------------------------------------------------------------------------------------
// BeamFollower

namespace {

BeamContext make_context(const TemplateModel& model, const FollowParams& params,
                         const BeamParams& beam) {
  BeamContext context(model.num_states(), beam, params.max_steps_per_frame);
  context.history() = FollowerHistory(model, params);
  return context;
}

}  // namespace

Result<BeamFollower> BeamFollower::create(const TemplateModel& model, const FollowParams& params,
                                          const BeamParams& beam) {
  Result<BeamForward> forward = BeamForward::create(model, params, beam);
  if (!forward.ok()) return forward.error();
  return BeamFollower(std::move(forward).value(), make_context(model, params, beam));
}

Result<BeamFollower> BeamFollower::create(const TemplateModel& model, const FollowParams& params,
                                          const BeamParams& beam,
                                          std::shared_ptr<const JumpCandidateIndex> index) {
  Result<BeamForward> forward = BeamForward::create(model, params, beam, std::move(index));
  if (!forward.ok()) return forward.error();
  return BeamFollower(std::move(forward).value(), make_context(model, params, beam));
}

}  // namespace duet
