// What the exact forward step (hmm_follower.h) and the beam step (beam_follower.h) both carry
// from frame to frame beside the forward variable: the running likelihood, the previous decision
// and the per-input estimators (tempo, jump gate, sensor noise, input filter, explained
// residual). One struct, so both followers configure and reset the same state.
#pragma once

#include "duet/follow/ceiling_lost_report.h"
#include "duet/follow/explained_residual.h"
#include "duet/follow/follow_params.h"
#include "duet/follow/held_place.h"
#include "duet/follow/jump_gate.h"
#include "duet/follow/noise_filter.h"
#include "duet/follow/sensor_noise.h"
#include "duet/follow/template_model.h"
#include "duet/follow/tempo_band.h"
#include "duet/follow/tracker.h"

namespace duet {

struct FollowerHistory {
  // Without a model: the sensor noise reads 0 and the input filter passes the input.
  FollowerHistory() = default;
  // The sensor noise estimator and the input filter sized for the model's posture dimensions and
  // rate, with the parameters' time constant, density and allowance. Allocates.
  FollowerHistory(const TemplateModel& model, const FollowParams& params);

  // Back to the first frame (the estimators keep their sizes). Allocates nothing.
  void reset() noexcept;

  // Whether this frame is an outlier whose evidence is set aside (FollowParams::gate_outliers):
  // its evidence would hand the pause state the majority, its best squared distance is beyond
  // outlier_pause_fraction of the pause level's (pause_distance_sq), and the previous frame was
  // followed (the first placement settled, the frame not lost) or an outlier of a run shorter
  // than outlier_max_s (whose first frame followed one that was).
  bool is_outlier(const FollowParams& params, bool pause_majority, float best_distance_sq,
                  float pause_distance_sq) const noexcept {
    return params.gate_outliers && pause_majority &&
           best_distance_sq > params.outlier_pause_fraction * pause_distance_sq &&
           previous_state >= 0 &&
           (previous_outlier ? outlier_run_s < params.outlier_max_s - 1e-6 : !previous_lost) &&
           jump_gate.held_a_place(params);
  }

  // Whether the input is lost by distance, with hysteresis: it turns lost once past the
  // noise-scaled lost distance (`unexplained`) on consecutive frames for
  // FollowParams::lost_confirm_s of input time (`frame_s`: the frame's template steps over the
  // template rate), and followed again once within it for as long, or after a longer spell lost
  // for FollowParams::found_confirm_s of the spell's time past the distance. A frame with no
  // features changes nothing.
  bool confirm_unexplained(const FollowParams& params, bool unexplained, bool missing,
                           double frame_s) noexcept {
    if (missing) return lost_by_distance;
    if (lost_by_distance && unexplained) lost_spell_s += frame_s;
    const double confirm_s =
        lost_by_distance ? params.found_confirm_s(lost_spell_s) : params.lost_confirm_s;
    if (unexplained == lost_by_distance) {
      against_s = 0.0;
    } else if ((against_s += frame_s) >= confirm_s - 1e-6) {
      lost_by_distance = unexplained;
      against_s = 0.0;
      lost_spell_s = 0.0;
    }
    return lost_by_distance;
  }

  // The lost flag a step reports (FollowResult::lost), once the frame's other decisions are made:
  // lost means no part of the library explains the input, by the emission's ceiling test
  // (CeilingLostReport, with `gate_lost` and `past_ceiling`) or by distance (`unexplained`:
  // the best match is past the noise-scaled lost distance, decided with confirm_unexplained's
  // hysteresis).
  bool report_lost(const FollowParams& params, bool gate_lost, bool past_ceiling, bool unexplained,
                   bool missing, double frame_s) noexcept {
    const bool by_distance = confirm_unexplained(params, unexplained, missing, frame_s);
    return ceiling_lost.report(params, gate_lost, past_ceiling, missing) || by_distance;
  }

  // Completes a step's result once its estimate and jump are decided, the same for the exact
  // and the beam step: lost (the emission's ceiling `result.lost`, the pause state, or
  // `unexplained`), the calibrated confidence, the dancer's tempo (taught by moves within the
  // band, `limits`), and this frame remembered for the next. Allocates nothing.
  void finish_step(const TemplateModel& model, const FollowParams& params,
                   const TempoLimits& limits, bool unexplained, double dt_s,
                   FollowResult& result) noexcept;

  double total_log_likelihood = 0.0;  // a sum over the whole performance, hence double
  long long frames = 0;
  int previous_state = -1;
  bool previous_lost = false;
  bool previous_outlier = false;   // the previous frame's evidence was set aside (outlier gate)
  double outlier_run_s = 0.0;      // input time of the outlier frames up to it, in a row
  bool lost_by_distance = false;   // confirm_unexplained's decision
  CeilingLostReport ceiling_lost;  // report_lost's ceiling test
  double against_s = 0.0;          // input time the frames have disagreed with it, consecutively
  double lost_spell_s = 0.0;       // input time past the distance since lost by it
  TempoEstimator tempo;
  JumpGate jump_gate;
  SensorNoiseEstimator sensor_noise;
  NoiseFilter noise_filter;
  ExplainedResidual explained_residual;
  HeldPlace
      held_place;  // how long the estimate has held one place (FollowParams::held_place_lost_s)
  double distance_spell_s = 0.0;      // input time lost by distance, consecutively
  int found_from_state = -1;          // the estimate where a found-again wait began; negative: none
  StillSinceFound still_since_found;  // FollowParams::found_still_spell_s
  double missing_s = 0.0;             // input time without evidence, consecutively (missing_lost_s)
  float evidence_confidence = -1.0f;  // the last frame with evidence's confidence; < 0: none yet
};

}  // namespace duet
