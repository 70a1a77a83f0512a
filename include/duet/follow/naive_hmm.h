// Baseline: the forward algorithm of eq. 10 with the full (M+1) x (M+1) transition matrix written
// out, O(M^2) per frame. Same model and same answers as HmmFollower (the tests check it); it exists
// to show what the factorisation of eq. 11 buys. The matrix is dense: limited to kMaxStates.
// The model must outlive the tracker.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string_view>
#include <vector>

#include "duet/base/result.h"
#include "duet/follow/ceiling_lost_report.h"
#include "duet/follow/follow_params.h"
#include "duet/follow/jump_gate.h"
#include "duet/follow/template_model.h"
#include "duet/follow/tempo_band.h"
#include "duet/follow/tracker.h"

namespace duet {

class NaiveHmmFollower final : public Tracker {
 public:
  static constexpr int kMaxStates = 8192;  // 8193^2 floats = 268 MB

  static Result<NaiveHmmFollower> create(const TemplateModel& model, const FollowParams& params);

  void reset() noexcept override;
  FollowResult step(std::span<const float> features, double dt_s) noexcept override;
  std::string_view name() const noexcept override { return "naive_hmm"; }

  // A(j -> i), j and i in [0, M]; index M is the pause state N.
  float transition(int from, int to) const { return transition_to_from_(to, from); }
  std::span<const float> alpha() const { return alpha_; }

 private:
  NaiveHmmFollower() = default;
  // Writes the columns out of the template states for this band (the pause column is fixed).
  void set_template_columns(const BandProbabilities& band) noexcept;

  const TemplateModel* model_ = nullptr;
  FollowParams params_;
  // Row i holds A(j -> i) for every j, so the predicted alpha is one row-major matrix-vector
  // product over all pairs (eq. 10).
  Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> transition_to_from_;
  BandProbabilities band_;  // normalised together with leave_, at the template's tempo
  float leave_ = 0.0f;
  TempoLimits tempo_limits_;
  TempoEstimator tempo_;
  JumpGate jump_gate_;
  float inv_two_sigma_sq_ = 0.0f;
  float log_pause_emission_ = 0.0f;
  float lost_distance_sq_ = 0.0f;
  std::vector<float> alpha_, scratch_, distance_sq_;
  int previous_state_ = -1;
  bool previous_lost_ = false;
  CeilingLostReport ceiling_lost_;
};

}  // namespace duet
