// Parameters of the follower HMM (method.md 4). Plain named fields; the defaults are a starting
// point to be replaced by measured values (method.md 7), the `paper` preset reproduces [4.2].
#pragma once

#include <vector>

#include "duet/base/result.h"

namespace duet {

struct FollowParams {
  // Transitions out of a template state j, per template-rate step (eq. 4-5): the band B (self
  // j->j, next j->j+1, skip j->j+2) and leave j->N. The four are normalised to sum to 1 at set-up,
  // so only their ratios matter. self = skip makes the band's mean advance exactly one frame per
  // step: the tempo prior is centred on the template's tempo, slower (self) and up to 2x faster
  // (skip) equally likely. A band favouring next lags behind fast dancers when the emission is
  // weak; one favouring self lags at template tempo.
  float self_prob = 0.30f;
  float next_prob = 0.35f;
  float skip_prob = 0.30f;
  float leave_prob = 0.05f;  // L_j, the same for every j

  // Pause state N (eq. 6): stay N->N with pause_stay_prob (A_NN), resume N->i with
  // (1 - A_NN) * R_i. R is uniform over the template states when resume_weights is empty,
  // otherwise resume_weights[i] (M non-negative weights, normalised at set-up).
  float pause_stay_prob = 0.90f;
  std::vector<float> resume_weights;

  // false gives the left-to-right HMM baseline: no pause state, no jump, and at the end of a
  // take the remaining band probabilities are renormalised (the last frame becomes absorbing).
  bool jump_enabled = true;

  // Emission (eq. 7): b_i(phi) = exp(-||phi - phi_i||^2 / (2 sigma^2)), in the units of the
  // standardised, weighted features. sigma sets how much one frame's evidence weighs against the
  // band's prior: too large and the estimate lags behind tempo changes (the prior wins), too small
  // and noise makes it jitter and jump. Chosen by `duet eval` on the 14 salsa duets
  // (docs/evaluation.md): with the features' block scaling two random template frames are about
  // 2.5 apart (squared) and frames 0.1 s apart about 0.25, so 0.7 let the prior win (78.6% within
  // 100 ms at 1.4x tempo) while 0.15 gives >= 97.5% in every case.
  float emission_sigma = 0.15f;

  // The pause state's emission is flat: the likelihood of a template frame at this mean squared
  // distance per dimension, i.e. b_N = exp(-pause_distance_per_dim * D / (2 sigma^2)). The pause
  // state (and through it the jump) wins when every reachable frame is farther than that. Keep
  // pause_distance_per_dim * D / (2 sigma^2) near 25 when changing sigma: larger and the pause
  // state's mass rounds to zero, so no jump is ever taken.
  float pause_distance_per_dim = 0.02f;

  // Lost: no template frame is within this mean squared distance per dimension of the input, or
  // the pause state holds most of the posterior mass.
  float lost_distance_per_dim = 0.05f;

  // Confidence: posterior mass within +/- this many template frames of the estimate (same take).
  int confidence_window_frames = 6;

  // Input at another rate: each input frame applies n = clamp(round(dt_s * template_fps), 1,
  // max_steps_per_frame) template-rate transitions before its emission.
  int max_steps_per_frame = 8;

  // The paper's hand-set values [4.2]: self = next = 0.33, leave = resume = 0.165 (resume is
  // 1 - A_NN, so A_NN = 0.835). The paper gives no skip probability: skip = 0. Rows are
  // normalised, so out of a template state self = next = 0.4 and leave = 0.2.
  static FollowParams paper();
  // The left-to-right HMM baseline: these defaults with jump_enabled = false.
  static FollowParams left_to_right();

  // Checks ranges and finiteness; num_states is M (for the size of resume_weights).
  Status validate(int num_states) const;
};

}  // namespace duet
