// The follower of method.md 4: an HMM over the template frames with a pause state N through which
// the dancer can jump anywhere in the library, updated by the O(M) forward step of eq. 11.
//
// Three pieces, ozz-animation style:
//   HmmForward      the per-frame algorithm: constants derived once from the model and the
//                   parameters; step() reads a context and writes a result.
//   ForwardContext  everything kept between frames (alpha and scratch buffers), sized once.
//   HmmFollower     both together behind the Tracker interface.
// The model must outlive every HmmForward / HmmFollower built on it (they keep a pointer).
#pragma once

#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "duet/base/result.h"
#include "duet/follow/follow_params.h"
#include "duet/follow/follower_history.h"
#include "duet/follow/noise_scaled_levels.h"
#include "duet/follow/template_model.h"
#include "duet/follow/tempo_band.h"
#include "duet/follow/tracker.h"

namespace duet {

namespace follow_detail {
struct EmissionDistance;  // src/follow/forward_common.h
}  // namespace follow_detail

// State between frames. alpha has M + 1 entries: the template states, then the pause state N.
// Float on purpose: the step streams alpha and the features every frame (memory bandwidth);
// alpha is renormalised every frame so float's range is never approached. Only the running
// log-likelihood, a sum over the whole performance, is kept in double.
class ForwardContext {
 public:
  ForwardContext() = default;
  // Sizes the buffers for num_states template states of num_dims features and resets. Allocates.
  ForwardContext(int num_states, int num_dims) { resize(num_states, num_dims); }
  void resize(int num_states, int num_dims);

  // Initial distribution: uniform over the template states (the dancer may start anywhere in the
  // library), nothing in the pause state.
  void reset() noexcept;

  int num_states() const { return num_states_; }
  // The normalised forward variable after the last step (posterior over M + 1 states).
  std::span<const float> alpha() const { return alpha_; }
  double total_log_likelihood() const { return history_.total_log_likelihood; }
  // The tempo the band is centred on (1 until the dancer has shown another one).
  float tempo() const { return history_.tempo.tempo(); }
  long long frames() const { return history_.frames; }
  // The estimators kept between frames (sized by HmmFollower::create; a context without them
  // reports no sensor noise and passes the input unfiltered).
  FollowerHistory& history() { return history_; }
  SensorNoiseEstimator& sensor_noise() { return history_.sensor_noise; }
  const SensorNoiseEstimator& sensor_noise() const { return history_.sensor_noise; }
  NoiseFilter& noise_filter() { return history_.noise_filter; }

 private:
  friend class HmmForward;

  int num_states_ = 0;
  std::vector<float> alpha_;        // M + 1
  std::vector<float> scratch_;      // M + 1, the next alpha while a transition is applied
  std::vector<float> distance_sq_;  // M, ||phi_t - phi_i||^2 of the current frame
  std::vector<float> carried_;      // D, a partly observed frame with the rest carried
  int carry_from_ = -1;             // the last fully observed, followed frame's estimate
  double carry_ahead_ = 0.0;        // template frames the dance has moved on since (at the tempo)
  FollowerHistory history_;
};

class HmmForward {
 public:
  // Validates params against the model. Allocates (only for non-uniform resume weights).
  static Result<HmmForward> create(const TemplateModel& model, const FollowParams& params);

  // One input frame (see Tracker::step for features and dt_s). The context must have been sized
  // for this model. Allocates nothing, throws nothing.
  FollowResult step(std::span<const float> features, double dt_s,
                    ForwardContext& context) const noexcept;

  // Template-rate transitions applied for an input frame dt_s after the previous one.
  int steps_for(double dt_s) const noexcept;

  const TemplateModel& model() const { return *model_; }
  const FollowParams& params() const { return params_; }

  // Normalised transition probabilities out of template state j (used by tests and docs):
  // band[d] = B(j -> j + d) for d = 0, 1, 2 (0 where j + d leaves the take) and leave = A(j -> N)
  // (eq. 4-5, including the band mass that the end of a take sends into the pause state).
  struct Row {
    float band[3];
    float leave;
  };
  Row row(int j) const noexcept { return row(j, band_); }
  // The same with the band tilted to a tempo (tempo_band.h), as step() uses it.
  Row row(int j, const BandProbabilities& band) const noexcept;
  // The band for a tempo: tilted when params().tempo_adaptive, the fixed band otherwise.
  BandProbabilities band_for(float tempo) const noexcept;
  // A(N -> N) and A(N -> i) (eq. 6).
  float pause_stay() const { return pause_stay_; }
  float resume(int i) const noexcept;

 private:
  friend class BeamForward;  // beam mode (beam_follower.h) reuses the constants and transition
  HmmForward() = default;
  // A partly observed frame (some dimensions NaN: a controller out of the headset's view,
  // FollowSession) into context.carried_: its unobserved dimensions carried along the dance, the
  // template's values where the last followed estimate is expected now (moved on at the tempo),
  // so near there they add nothing to the distances and the observed ones decide. That estimate
  // is a fully observed frame's, or a partly observed one's close to where the carry expected it:
  // carried from wherever the partial frames moved, they held the estimate there (a wrong take
  // after a stall, `stalls` 0.5 -> 0.9 false jumps a minute). False, writing nothing, without
  // such an estimate within kMaxCarryS.
  bool carry_unobserved(std::span<const float> features, int steps,
                        ForwardContext& context) const noexcept;
  // After a frame: the place partly observed frames are carried from (carry_unobserved).
  void note_carry_anchor(bool observed, const FollowResult& result,
                         ForwardContext& context) const noexcept;
  // alpha_{t-1} -> sum_j alpha_{t-1}(j) A(j -> i) for every i, in O(M) (the bracket of eq. 11).
  void transition(const float* alpha, const BandProbabilities& band, float* next) const noexcept;
  // The emission of every state (eq. 7) and the outer factor of eq. 10/11 for the input phi at
  // this sensor noise: alpha (M + 1, the prediction) becomes the posterior, through scratch (the
  // two are swapped), and distance_sq (M) receives the distances. An outlier frame
  // (FollowParams::gate_outliers, judged from history) keeps the prediction alone. Sets
  // result.outlier, log_likelihood, best_distance_per_dim and lost (the fixed ceiling, on the
  // plain distance; the pause state's share is added by the caller) and returns the best squared
  // distances, bounded and plain.
  follow_detail::EmissionDistance emit_all_states(const float* phi, float noise,
                                                  const FollowerHistory& history,
                                                  std::vector<float>& alpha,
                                                  std::vector<float>& scratch, float* distance_sq,
                                                  FollowResult& result) const noexcept;

  const TemplateModel* model_ = nullptr;
  FollowParams params_;
  BandProbabilities band_;  // normalised with leave_: the interior rows at the template's tempo
  float leave_ = 0.0f;
  TempoLimits tempo_limits_;
  float pause_stay_ = 0.0f;
  std::vector<float> resume_;       // R_i, normalised; empty = uniform 1/M
  NoiseScaledLevels noise_levels_;  // the emission scale, pause level and lost distance
};

// HmmForward + ForwardContext behind the Tracker interface. FollowParams::left_to_right() gives
// the left-to-right baseline.
class HmmFollower final : public Tracker {
 public:
  static Result<HmmFollower> create(const TemplateModel& model, const FollowParams& params);

  void reset() noexcept override { context_.reset(); }
  FollowResult step(std::span<const float> features, double dt_s) noexcept override {
    return forward_.step(features, dt_s, context_);
  }
  std::string_view name() const noexcept override {
    return forward_.params().jump_enabled ? "hmm" : "left_to_right_hmm";
  }

  const HmmForward& forward() const { return forward_; }
  const ForwardContext& context() const { return context_; }

 private:
  HmmFollower(HmmForward forward, ForwardContext context)
      : forward_(std::move(forward)), context_(std::move(context)) {}

  HmmForward forward_;
  ForwardContext context_;
};

}  // namespace duet
