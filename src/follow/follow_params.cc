#include "duet/follow/follow_params.h"

#include <cmath>
#include <limits>
#include <string>

namespace duet {
namespace {

Error params_error(const std::string& reason) { return make_error("follow parameters", 0, reason); }

bool is_probability(float p) { return std::isfinite(p) && p >= 0.0f && p <= 1.0f; }

}  // namespace

TempoLimits FollowParams::tempo_limits(double template_fps) const {
  TempoLimits limits;
  limits.time_constant_s = tempo_time_constant_s;
  limits.min_tempo = min_tempo;
  limits.max_tempo = max_tempo;
  limits.hold_window_s = tempo_hold_window_s;
  limits.hold_advance = tempo_hold_advance;
  limits.template_fps = template_fps;
  limits.hold_max_s = tempo_hold_max_s;
  return limits;
}

FollowParams FollowParams::paper() {
  FollowParams params;
  params.self_prob = 0.33f;
  params.next_prob = 0.33f;
  params.skip_prob = 0.0f;
  params.leave_prob = 0.165f;
  params.pause_stay_prob = 1.0f - 0.165f;
  params.tempo_adaptive = false;
  params.jump_hold_s = 0.0f;
  params.jump_tolerance_frames = 0;
  params.jump_settle_s = 0.0f;
  params.jump_settle_mass = 0.0f;
  params.jump_settle_advance_s = 0.0f;
  params.jump_burst_jumps = 0;
  params.jump_catch_up_s = 0.0f;
  params.noisy_jump_hold_s = 0.0f;
  params.unexplained_jump_hold_s = 0.0f;
  params.limb_outlier_ratio = std::numeric_limits<float>::infinity();
  params.jump_old_place_mass = 1.0f;
  params.jump_alike_distance_per_dim = 0.0f;
  params.gate_outliers = false;
  params.pause_noise_factor = 0.0f;
  params.emission_noise_factor = 0.0f;
  params.emission_noise_allowance = 0.0f;
  params.noise_filter_density = 0.0f;
  params.calibrate_confidence = false;
  params.lost_residual_per_dim = std::numeric_limits<float>::infinity();
  params.lost_confirm_s = 0.0f;
  params.found_confirm_per_lost_s = 0.0f;
  params.pause_reported_lost = true;
  params.held_place_lost_s = 0.0f;
  params.found_still_spell_s = 0.0f;
  params.missing_lost_s = 0.0f;
  return params;
}

FollowParams FollowParams::left_to_right() {
  FollowParams params;
  params.jump_enabled = false;
  return params;
}

Status FollowParams::validate(int num_states) const {
  const struct {
    const char* name;
    float value;
  } probabilities[] = {{"self_prob", self_prob},
                       {"next_prob", next_prob},
                       {"skip_prob", skip_prob},
                       {"leave_prob", leave_prob},
                       {"pause_stay_prob", pause_stay_prob}};
  for (const auto& p : probabilities) {
    if (!is_probability(p.value)) {
      return params_error(std::string(p.name) + " must be in [0, 1], got " +
                          std::to_string(p.value));
    }
  }
  const float band = self_prob + next_prob + skip_prob;
  if (band <= 0.0f) return params_error("self_prob + next_prob + skip_prob must be positive");
  if (!(emission_sigma >= 1e-3f && std::isfinite(emission_sigma))) {
    return params_error("emission_sigma must be finite and >= 0.001, got " +
                        std::to_string(emission_sigma));
  }
  if (!(pause_distance_per_dim >= 0.0f && std::isfinite(pause_distance_per_dim))) {
    return params_error("pause_distance_per_dim must be finite and >= 0, got " +
                        std::to_string(pause_distance_per_dim));
  }
  if (!(velocity_distance_cap >= 0.0f)) {  // +inf allowed: no cap
    return params_error("velocity_distance_cap must be >= 0, got " +
                        std::to_string(velocity_distance_cap));
  }
  if (!(limb_outlier_ratio >= 1.0f)) {  // +inf allowed: no bound
    return params_error("limb_outlier_ratio must be >= 1, got " +
                        std::to_string(limb_outlier_ratio));
  }
  if (!(limb_outlier_floor >= 0.0f && std::isfinite(limb_outlier_floor))) {
    return params_error("limb_outlier_floor must be finite and >= 0, got " +
                        std::to_string(limb_outlier_floor));
  }
  if (!(lost_velocity_cap_per_dim >= 0.0f)) {  // +inf allowed: the emission's cap
    return params_error("lost_velocity_cap_per_dim must be >= 0, got " +
                        std::to_string(lost_velocity_cap_per_dim));
  }
  if (!(lost_distance_per_dim >= 0.0f)) {  // +inf allowed: never lost by distance
    return params_error("lost_distance_per_dim must be >= 0, got " +
                        std::to_string(lost_distance_per_dim));
  }
  if (!(held_place_reach_s > 0.0f && std::isfinite(held_place_reach_s))) {
    return params_error("held_place_reach_s must be finite and > 0, got " +
                        std::to_string(held_place_reach_s));
  }
  if (!(found_still_reach_s > 0.0f && std::isfinite(found_still_reach_s))) {
    return params_error("found_still_reach_s must be finite and > 0, got " +
                        std::to_string(found_still_reach_s));
  }
  if (!(sensor_noise_time_constant_s > 0.0 && std::isfinite(sensor_noise_time_constant_s))) {
    return params_error("sensor_noise_time_constant_s must be finite and > 0, got " +
                        std::to_string(sensor_noise_time_constant_s));
  }
  const struct {
    const char* name;
    float value;
  } non_negative[] = {{"pause_noise_factor", pause_noise_factor},
                      {"pause_noise_allowance", pause_noise_allowance},
                      {"lost_noise_factor", lost_noise_factor},
                      {"lost_residual_factor", lost_residual_factor},
                      {"emission_noise_factor", emission_noise_factor},
                      {"emission_noise_allowance", emission_noise_allowance},
                      {"noise_filter_density", noise_filter_density},
                      {"noise_filter_allowance", noise_filter_allowance},
                      {"held_place_lost_s", held_place_lost_s},
                      {"found_still_spell_s", found_still_spell_s},
                      {"missing_lost_s", missing_lost_s}};
  for (const auto& level : non_negative) {
    if (!(level.value >= 0.0f && std::isfinite(level.value))) {
      return params_error(std::string(level.name) + " must be finite and >= 0, got " +
                          std::to_string(level.value));
    }
  }
  if (!(lost_residual_per_dim >= 0.0f)) {  // +inf allowed: the fixed lost_distance_per_dim
    return params_error("lost_residual_per_dim must be >= 0, got " +
                        std::to_string(lost_residual_per_dim));
  }
  // Times (and one factor of a time) bounded to [0, max].
  const struct {
    const char* name;
    float value;
    int max;
    const char* unit;
  } bounded[] = {{"lost_confirm_s", lost_confirm_s, 10, " s"},
                 {"found_confirm_per_lost_s", found_confirm_per_lost_s, 10, ""},
                 {"found_confirm_max_s", found_confirm_max_s, 10, " s"},
                 {"outlier_max_s", outlier_max_s, 10, " s"},
                 {"jump_hold_s", jump_hold_s, 10, " s"},
                 {"noisy_jump_hold_s", noisy_jump_hold_s, 10, " s"},
                 {"unexplained_jump_hold_s", unexplained_jump_hold_s, 10, " s"},
                 {"unexplained_jump_hold_after_s", unexplained_jump_hold_after_s, 60, " s"},
                 {"jump_settle_s", jump_settle_s, 10, " s"},
                 {"jump_settle_advance_s", jump_settle_advance_s, 10, " s"},
                 {"jump_burst_s", jump_burst_s, 60, " s"},
                 {"jump_catch_up_s", jump_catch_up_s, 10, " s"}};
  for (const auto& b : bounded) {
    if (!(b.value >= 0.0f && b.value <= static_cast<float>(b.max))) {
      return params_error(std::string(b.name) + " must be in [0, " + std::to_string(b.max) + "]" +
                          b.unit + ", got " + std::to_string(b.value));
    }
  }
  if (confidence_window_frames < 0) {
    return params_error("confidence_window_frames must be >= 0, got " +
                        std::to_string(confidence_window_frames));
  }
  if (!(unexplained_jump_ratio > 0.0f && std::isfinite(unexplained_jump_ratio))) {
    return params_error("unexplained_jump_ratio must be finite and > 0, got " +
                        std::to_string(unexplained_jump_ratio));
  }
  if (!(jump_old_place_mass >= 0.0f && jump_old_place_mass <= 1.0f)) {
    return params_error("jump_old_place_mass must be in [0, 1], got " +
                        std::to_string(jump_old_place_mass));
  }
  if (!(jump_alike_distance_per_dim >= 0.0f && std::isfinite(jump_alike_distance_per_dim))) {
    return params_error("jump_alike_distance_per_dim must be finite and >= 0, got " +
                        std::to_string(jump_alike_distance_per_dim));
  }
  if (!(noisy_jump_hold_level > 0.0f && std::isfinite(noisy_jump_hold_level))) {
    return params_error("noisy_jump_hold_level must be finite and > 0, got " +
                        std::to_string(noisy_jump_hold_level));
  }
  if (!(jump_settle_mass >= 0.0f && jump_settle_mass <= 1.0f)) {
    return params_error("jump_settle_mass must be in [0, 1], got " +
                        std::to_string(jump_settle_mass));
  }
  if (!(outlier_pause_fraction >= 0.0f && std::isfinite(outlier_pause_fraction))) {
    return params_error("outlier_pause_fraction must be finite and >= 0, got " +
                        std::to_string(outlier_pause_fraction));
  }
  if (jump_burst_jumps < 0 || jump_burst_jumps > kMaxJumpBurstJumps) {
    return params_error("jump_burst_jumps must be in [0, " + std::to_string(kMaxJumpBurstJumps) +
                        "], got " + std::to_string(jump_burst_jumps));
  }
  if (jump_tolerance_frames < 0 || jump_tolerance_frames > 1000) {
    return params_error("jump_tolerance_frames must be in [0, 1000], got " +
                        std::to_string(jump_tolerance_frames));
  }
  if (max_steps_per_frame < 1 || max_steps_per_frame > 1000) {
    return params_error("max_steps_per_frame must be in [1, 1000], got " +
                        std::to_string(max_steps_per_frame));
  }
  if (tempo_adaptive) {
    if (!(tempo_time_constant_s > 0.0 && std::isfinite(tempo_time_constant_s))) {
      return params_error("tempo_time_constant_s must be finite and > 0, got " +
                          std::to_string(tempo_time_constant_s));
    }
    if (!(min_tempo > 0.0f && max_tempo >= min_tempo && max_tempo < 2.0f)) {
      return params_error("the tempo range needs 0 < min_tempo <= max_tempo < 2, got [" +
                          std::to_string(min_tempo) + ", " + std::to_string(max_tempo) + "]");
    }
    if (!(tempo_hold_window_s >= 0.0f && tempo_hold_window_s <= 2.0f)) {
      return params_error("tempo_hold_window_s must be in [0, 2] s, got " +
                          std::to_string(tempo_hold_window_s));
    }
    if (!(tempo_hold_max_s >= 0.0f && std::isfinite(tempo_hold_max_s))) {
      return params_error("tempo_hold_max_s must be finite and >= 0, got " +
                          std::to_string(tempo_hold_max_s));
    }
    if (!(tempo_hold_advance >= 0.0f && tempo_hold_advance < 2.0f)) {
      return params_error("tempo_hold_advance must be in [0, 2) frames a step, got " +
                          std::to_string(tempo_hold_advance));
    }
    if (!(self_prob > 0.0f && skip_prob > 0.0f)) {
      return params_error(
          "tempo_adaptive needs self_prob > 0 and skip_prob > 0 (slower and "
          "faster moves to tilt the band towards)");
    }
  }
  if (!resume_weights.empty()) {
    if (static_cast<int>(resume_weights.size()) != num_states) {
      return params_error("resume_weights has " + std::to_string(resume_weights.size()) +
                          " entries, the template has " + std::to_string(num_states) + " states");
    }
    double sum = 0.0;
    for (std::size_t i = 0; i < resume_weights.size(); ++i) {
      if (!(resume_weights[i] >= 0.0f && std::isfinite(resume_weights[i]))) {
        return params_error("resume_weights[" + std::to_string(i) +
                            "] must be finite and >= 0, got " + std::to_string(resume_weights[i]));
      }
      sum += resume_weights[i];
    }
    if (!(sum > 0.0)) return params_error("resume_weights sum to zero");
  }
  return Ok{};
}

}  // namespace duet
