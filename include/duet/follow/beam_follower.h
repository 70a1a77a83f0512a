// Beam mode of the HMM follower (issue 13): per frame, emissions only for the states that carry
// forward mass (and the band successors they reach), plus the jump candidates nearest the input
// (JumpCandidateIndex). The cost per frame depends on the beam, not on the library.
//
// The model is the one of hmm_follower.h, with the same transitions, emission and decisions.
// What makes the beam exact enough:
//   - The jump term factorises through the pause state (method.md 4): every state receives
//     (1 - A_NN) * alpha(N) * R_i. That share is kept as one number (the background), so the
//     pause state's mass is accounted exactly; the background reaches the emission only at the
//     beam and the jump candidates.
//   - Every state left out is at least the index's bound away from the input, so the mass each
//     would have carried is bounded (the background's share times the bound's emission). When
//     that could change a decision (the maximum, the confidence, the pause state's majority, or
//     lost: the best distance of the library), the search is widened: first to more nearest
//     candidates, then to every state within the bound beyond which no left-out state could
//     change it (a radius search of the index, when it holds at most
//     BeamParams::radius_candidates states). When even that cannot settle the frame, or the
//     beam grows past BeamParams::max_states, the frame is finished by the full (exact) step,
//     and the beam is rebuilt from its posterior.
//     Otherwise the posterior is normalised over the states kept: the left-out mass (spread over
//     the far states, where the exact step keeps it below a per-state bound) is dropped, and the
//     frame's log-likelihood misses it.
//   - States whose posterior falls below prune_ratio times the maximum leave the beam (far
//     below it, deep_prune_ratio, until the first placement has settled, and for a few states
//     that fit the input about as well as the best one).
// The first frame after reset() is a full step (the initial distribution is uniform).
// One departure from the exact step, for cost: a spell lost for long takes the full step only
// now and then (BeamParams::lost_full_step_s).
// Only for the jump HMM: a left-to-right HMM (no pause state) recovers from a wrong place only
// through the little mass it keeps everywhere, which a beam drops (measured: up to 2.4 points of
// accuracy apart even at a prune ratio of 1e-20), so create() rejects it.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "duet/base/result.h"
#include "duet/follow/follow_params.h"
#include "duet/follow/follower_history.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/jump_candidates.h"
#include "duet/follow/jump_gate.h"
#include "duet/follow/noise_filter.h"
#include "duet/follow/tempo_band.h"
#include "duet/follow/template_model.h"
#include "duet/follow/tracker.h"

namespace duet {

struct BeamParams {
  // Jump candidates per frame: the states nearest the input in the index's projection. When
  // they leave the frame uncertain (see above), the search is widened to wide_jump_candidates
  // before the full step is taken.
  int jump_candidates = 16;
  int wide_jump_candidates = 128;
  // Still uncertain, every state within the bound that would settle the frame is taken (a radius
  // search of the index), when there are at most this many; more, and the full step finishes
  // the frame.
  int radius_candidates = 4096;
  // A state leaves the beam when its posterior is below this times the largest one.
  float prune_ratio = 1e-8f;
  // ... and this until the first placement has settled (JumpGate::settled), as long as it keeps
  // at most half of max_states: a standing start spreads the posterior over look-alike frames of
  // many takes, and a place whose mass fell below 1e-8 of the maximum for a moment there was the
  // dance a second later (`suit-drift`, every take: 95.16 % within 100 ms at 1e-8 throughout,
  // the exact step's 95.90, docs/follower.md "Beam mode").
  float deep_prune_ratio = 1e-20f;
  // Once settled, up to well_fitting_states states a frame (the first in the library's order)
  // stay down to deep_prune_ratio when their emission is within well_fitting_ratio of the best
  // one's: a place that fits the input as well as the one followed, its mass far below, is where
  // the exact step finds the dance again once the place followed stops fitting (`clean@asf`,
  // take 60_13: the beam stayed on 60_06 where the exact step moved to 60_13 after 3 s; every
  // take 98.63 against the exact step's 98.87 %). 0 states: none.
  float well_fitting_ratio = 10.0f;
  int well_fitting_states = 32;
  // Above this many states the next frame is a full step (a beam this wide saves nothing).
  int max_states = 4096;
  // A full step finishes the frame when the mass the left-out states may carry within one
  // confidence window exceeds this fraction of the kept mass (or could be the maximum, or could
  // turn the pause state's majority).
  float outside_mass_tolerance = 1e-3f;
  // While a spell lost lasts, the full step is taken at most once per lost_full_step_s of input
  // time, once the input has been lost by distance for lost_spell_before_s (a dance flagged lost
  // for a moment, three points on another rig, stays exact). Between full steps, with a beam,
  // the emission over the beam and the wide candidates finishes the frame although the states
  // left out could change a decision; with none, a frame that neither the place reported before
  // nor the nearest candidates explain weighs no evidence, as a missing frame (its transitions
  // wait for the next full step). Deciding "lost" exactly needs every state within the lost
  // distance ruled out, which the index's bound cannot do: a lost user took the full step on
  // every frame (14 ms at 1M states; docs/follower.md "Beam mode"). lost_full_step_s 0: every
  // such frame takes the full step.
  double lost_full_step_s = 0.5;
  double lost_spell_before_s = 2.0;

  Status validate() const;

  // The defaults, with the pruning deepened to 1e-20 for a fixed band or a band without skip
  // (the paper preset): such a band lags behind a faster dancer and its estimate rides on mass
  // far below the maximum. Measured with `duet eval --trackers hmm-paper --beam`: up to 11 points
  // of accuracy lost at 1e-8, 0.8 at 1e-14, at most 0.13 at 1e-20 (docs/follower.md).
  static BeamParams suited_to(const FollowParams& params);
};

// State between frames: the dense forward variable (zero outside the beam), the beam's states
// and the buffers of one frame, sized once.
class BeamContext {
 public:
  BeamContext() = default;
  // Sizes the buffers for num_states states, beam params and max_steps_per_frame. Allocates.
  BeamContext(int num_states, const BeamParams& beam, int max_steps_per_frame);

  // Uniform over the template states; the next step is a full one.
  void reset() noexcept;

  int num_states() const { return num_states_; }
  // The posterior over M + 1 states after the last step (the states outside the beam hold 0).
  std::span<const float> alpha() const { return alpha_; }
  // States in the beam after the last step (0 when that step left the full distribution).
  int beam_size() const { return full_next_ ? 0 : static_cast<int>(beam_.size()); }
  // Frames that took the full step (the first one, and every fallback).
  long long full_steps() const { return full_steps_; }
  FollowerHistory& history() { return history_; }
  SensorNoiseEstimator& sensor_noise() { return history_.sensor_noise; }
  NoiseFilter& noise_filter() { return history_.noise_filter; }
  long long frames() const { return history_.frames; }
  double total_log_likelihood() const { return history_.total_log_likelihood; }
  float tempo() const { return history_.tempo.tempo(); }

 private:
  friend class BeamForward;

  int num_states_ = 0;
  std::vector<float> alpha_;        // M + 1, dense; outside beam_ zero unless full_next_
  std::vector<float> scratch_;      // M + 1, dense; zero outside next_ between frames
  std::vector<float> distance_sq_;  // M for the full step; the beam's distances otherwise
  std::vector<int> beam_;           // sorted states of the beam
  std::vector<int> next_;           // sorted states being built (transition, merge)
  std::vector<float> weighted_;     // per state of next_: predicted * emission
  std::vector<std::uint32_t> candidates_;
  std::vector<float> candidate_d2_;
  float background_ = 0.0f;  // resumed mass per unit of R_i, not yet in alpha_
  bool full_next_ = true;
  // Lost between full steps (BeamParams::lost_full_step_s): the template steps whose transitions
  // wait for the next full step, and the input time since the last one.
  int deferred_steps_ = 0;
  double since_full_s_ = 0.0;
  long long full_steps_ = 0;
  // Tempo, jump gate, sensor noise (which scales the pause level and lost distance), input
  // filter and explained residual, as HmmForward's.
  FollowerHistory history_;
  float frame_noise_ = 0.0f;  // the sensor noise estimated at the current frame
};

class BeamForward {
 public:
  // Validates the parameters and builds the jump candidate index (allocates, O(M log M)).
  static Result<BeamForward> create(const TemplateModel& model, const FollowParams& params,
                                    const BeamParams& beam = {});
  // The same with an index already built for this model (e.g. read from the model cache),
  // shared with other followers of the same model.
  static Result<BeamForward> create(const TemplateModel& model, const FollowParams& params,
                                    const BeamParams& beam,
                                    std::shared_ptr<const JumpCandidateIndex> index);

  // One input frame, as HmmForward::step. Allocates nothing, throws nothing.
  FollowResult step(std::span<const float> features, double dt_s,
                    BeamContext& context) const noexcept;

  const HmmForward& exact() const { return exact_; }
  const BeamParams& beam_params() const { return beam_; }
  const JumpCandidateIndex& index() const { return *index_; }

 private:
  BeamForward(HmmForward exact, std::shared_ptr<const JumpCandidateIndex> index,
              const BeamParams& beam)
      : exact_(std::move(exact)), index_(std::move(index)), beam_(beam) {}

  float resume_share(int i) const noexcept;  // R_i
  void sparse_transition(const BandProbabilities& band, BeamContext& context) const noexcept;
  // Jump candidates of one frame, sorted in context.candidates_[0..found); every other state is
  // at least `bound` away when `bounded` (false: the search returned every state it could).
  struct CandidateSet {
    int found = 0;
    float bound = 0.0f;
    bool bounded = false;
  };
  CandidateSet nearest_candidates(const float* phi, int k, BeamContext& context) const noexcept;
  // Every state within radius_sq in the projection; found -1 when more than
  // BeamParams::radius_candidates are.
  CandidateSet candidates_within(const float* phi, float radius_sq,
                                 BeamContext& context) const noexcept;
  // The emission over the beam and the candidates, with the usual, then the wide candidates,
  // then the states within the bound that settles the frame; false when none settles it and the
  // full step must finish the frame.
  // accept_unsettled (a spell lost between full steps): the wide candidates' emission finishes
  // the frame even when the states left out could change a decision (no radius search, no full
  // step).
  bool sparse_step(const float* phi, BeamContext& context, FollowResult& result,
                   bool accept_unsettled = false) const noexcept;
  // Emission over the beam and these candidates; false (context unchanged but for next_) when
  // the states left out could change a decision. settling_bound is then the bound beyond which
  // they could not (FLT_MAX: none).
  // must_settle false (a spell lost between full steps): accepted whatever the states left out.
  bool sparse_emission(const float* phi, const CandidateSet& candidates, BeamContext& context,
                       FollowResult& result, float& settling_bound,
                       bool must_settle = true) const noexcept;
  // Adds the background to every state (the dense prediction of the full step).
  void materialise(BeamContext& context) const noexcept;
  // A frame without evidence (missing, or an outlier set aside): the beam, the background and
  // the pause state renormalised together, as the transitions left them.
  void renormalise_without_evidence(BeamContext& context) const noexcept;
  // After a full step: the states above the prune threshold become the beam, unless too many.
  void rebuild_beam(BeamContext& context) const noexcept;
  // The mass below which a state leaves the beam, of states holding `masses` (the largest
  // `largest`): BeamParams::deep_prune_ratio times the largest until the first placement
  // has settled, while that keeps at most half of BeamParams::max_states; else prune_ratio times
  // it.
  float prune_threshold(const BeamContext& context, std::span<const float> masses,
                        float largest) const noexcept;
  // Whether the frame falls in a spell lost between full steps (BeamParams::lost_full_step_s).
  bool between_full_steps(double dt_s, const BeamContext& context) const noexcept;
  // Whether neither the place reported before nor any of the nearest jump candidates is within
  // the lost distance; if so, sets result's best distance and fixed-ceiling lost flag.
  bool unexplained_nearby(const float* phi, BeamContext& context,
                          FollowResult& result) const noexcept;
  int sparse_argmax(const BeamContext& context) const noexcept;

  HmmForward exact_;
  std::shared_ptr<const JumpCandidateIndex> index_;  // never null
  BeamParams beam_;
  float max_resume_share_ = 0.0f;  // max_i R_i
};

// BeamForward + BeamContext behind the Tracker interface.
class BeamFollower final : public Tracker {
 public:
  static Result<BeamFollower> create(const TemplateModel& model, const FollowParams& params,
                                     const BeamParams& beam = {});
  static Result<BeamFollower> create(const TemplateModel& model, const FollowParams& params,
                                     const BeamParams& beam,
                                     std::shared_ptr<const JumpCandidateIndex> index);

  void reset() noexcept override { context_.reset(); }
  FollowResult step(std::span<const float> features, double dt_s) noexcept override {
    return forward_.step(features, dt_s, context_);
  }
  std::string_view name() const noexcept override { return "hmm"; }

  const BeamForward& forward() const { return forward_; }
  const BeamContext& context() const { return context_; }

 private:
  BeamFollower(BeamForward forward, BeamContext context)
      : forward_(std::move(forward)), context_(std::move(context)) {}

  BeamForward forward_;
  BeamContext context_;
};

}  // namespace duet
