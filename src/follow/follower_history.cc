#include "duet/follow/follower_history.h"

#include <algorithm>
#include <cmath>

#include "duet/follow/confidence_calibration.h"
#include "forward_common.h"

namespace duet {

FollowerHistory::FollowerHistory(const TemplateModel& model, const FollowParams& params)
    : sensor_noise(model.num_dims() - model.velocity_dims(), params.sensor_noise_time_constant_s,
                   model.frame_rate_hz()),
      noise_filter(model.num_dims(), model.num_dims() - model.velocity_dims(),
                   params.noise_filter_density, params.noise_filter_allowance,
                   model.frame_rate_hz()) {}

void FollowerHistory::reset() noexcept {
  total_log_likelihood = 0.0;
  frames = 0;
  previous_state = -1;
  previous_lost = false;
  previous_outlier = false;
  outlier_run_s = 0.0;
  lost_by_distance = false;
  ceiling_lost.reset();
  against_s = 0.0;
  lost_spell_s = 0.0;
  tempo.reset();
  jump_gate.reset();
  sensor_noise.reset();
  noise_filter.reset();
  explained_residual.reset();
  held_place.reset();
  distance_spell_s = 0.0;
  found_from_state = -1;
  still_since_found.reset();
  missing_s = 0.0;
  evidence_confidence = -1.0f;
}

void FollowerHistory::finish_step(const TemplateModel& model, const FollowParams& params,
                                  const TempoLimits& limits, bool unexplained, double dt_s,
                                  FollowResult& result) noexcept {
  const bool past_ceiling = result.lost;  // the emission's test (false without features)
  result.lost = result.missing ? previous_lost : (result.lost || result.in_pause);
  if (params.calibrate_confidence) {
    result.confidence =
        ConfidenceCalibration::apply(result.window_mass, result.sensor_noise_per_dim);
    // Without evidence the band only spreads, and its mass within the window falls (to about 0.4
    // in 2 s), but the tempo carries the estimate on: `stalls` was 99.7 % within 100 ms with a
    // mean confidence of ~0.4 on its held frames (calibration error 9.7 %). The last evidence's
    // confidence stands until missing_lost_s.
    if (result.missing && evidence_confidence >= 0.0f) result.confidence = evidence_confidence;
  }
  if (!result.missing) evidence_confidence = result.confidence;
  if (params.tempo_adaptive) {
    const bool band_move = !result.missing && !result.lost && !result.jumped;
    tempo.update(previous_state, result.state, result.steps, dt_s, band_move, limits);
  }
  tempo.observe_rate(result.steps, dt_s, model.frame_rate_hz(), limits);
  if (params.tempo_adaptive) tempo.start_at_template_tempo(limits);
  result.tempo = tempo.dancer_tempo();
  total_log_likelihood += result.log_likelihood;
  ++frames;
  const int advanced = previous_state >= 0 && result.state >= 0 ? result.state - previous_state : 0;
  // A move out of the band's reach the follower did not call a jump (before the first placement
  // settles none is, JumpGate) is the estimate being refined, not a dancer's pace.
  const bool moved_far = model.is_jump(previous_state, result.state, std::max(result.steps, 1),
                                       params.jump_tolerance_frames);
  previous_state = result.state;
  previous_lost = result.lost;
  previous_outlier = result.outlier;
  outlier_run_s = result.outlier ? outlier_run_s + result.steps / model.frame_rate_hz() : 0.0;
  // A limb out of line at the estimate (a held arm, a wave) is not the rig's residual: taught, it
  // raised the lost level (the Bandai wave looped for 30 s, limb floor 0.05: 82 % lost against
  // 89 % untaught; FollowParams::limb_outlier_ratio).
  explained_residual.update(result.best_distance_per_dim,
                            !result.missing && !result.outlier && !result.in_pause &&
                                !result.jumped && !result.limb_out_of_line,
                            moved_far ? 0 : advanced, dt_s, model.frame_rate_hz());
  const bool lost_by_distance_before = lost_by_distance;
  result.lost = report_lost(params, result.lost, past_ceiling, unexplained, result.missing,
                            result.steps / model.frame_rate_hz());
  // The estimate at the first frame back within the lost distance while lost (the found-again
  // wait's first frame): StillSinceFound measures the dancer's move on from there.
  if (!result.missing) {
    const bool waiting = lost_by_distance_before && !unexplained;
    if (!waiting) {
      found_from_state = -1;
    } else if (found_from_state < 0) {
      found_from_state = result.state;
    }
  }
  if (lost_by_distance && dt_s > 0.0 && std::isfinite(dt_s)) distance_spell_s += dt_s;
  const bool found_after_spell = params.found_still_spell_s > 0.0f && lost_by_distance_before &&
                                 !lost_by_distance &&
                                 distance_spell_s >= params.found_still_spell_s - 1e-6;
  if (!lost_by_distance) distance_spell_s = 0.0;
  const auto reach_states = [&](float reach_s) {
    return std::max(1, static_cast<int>(std::lround(reach_s * model.frame_rate_hz())));
  };
  held_place.update(result.state, result.jumped, dt_s, reach_states(params.held_place_reach_s));
  still_since_found.update(result.state, result.jumped, found_after_spell ? found_from_state : -1,
                           reach_states(params.found_still_reach_s));
  if (!lost_by_distance) found_from_state = -1;
  if (still_since_found.still() && !result.lost) {
    result.lost = true;
    result.held_still = true;
    result.still_since_lost = true;
  }
  if (params.held_place_lost_s > 0.0f && held_place.held_s() > params.held_place_lost_s &&
      !result.lost) {
    result.lost = true;
    result.held_still = true;
  }
  if (!result.missing) {
    missing_s = 0.0;
  } else if (dt_s > 0.0 && std::isfinite(dt_s)) {
    missing_s += dt_s;
  }
  if (params.missing_lost_s > 0.0f && missing_s > params.missing_lost_s) {
    result.lost = true;
    result.confidence = 0.0f;
  }
}

}  // namespace duet
