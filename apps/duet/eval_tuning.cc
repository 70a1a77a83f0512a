#include "eval_tuning.h"

#include <string>

#include "number_checks.h"

namespace duet::app {

namespace {

// One float field of FollowParams that a tuning option sets.
struct FloatRow {
  const char* flag;
  float FollowParams::*field;
  std::string help;
  CLI::Validator check;
};

const std::vector<FloatRow>& float_rows() {
  static const std::vector<FloatRow> rows = {
      {"--sigma", &FollowParams::emission_sigma, "Emission sigma (all HMM variants)",
       positive_check()},
      {"--self", &FollowParams::self_prob, "self_prob", number_between(0.0, 1.0)},
      {"--next", &FollowParams::next_prob, "next_prob", number_between(0.0, 1.0)},
      {"--skip", &FollowParams::skip_prob, "skip_prob", number_between(0.0, 1.0)},
      {"--leave", &FollowParams::leave_prob, "leave_prob", number_between(0.0, 1.0)},
      {"--pause-stay", &FollowParams::pause_stay_prob, "pause_stay_prob (A_NN)",
       number_between(0.0, 1.0)},
      {"--pause-distance", &FollowParams::pause_distance_per_dim,
       "pause_distance_per_dim (all HMM variants)", non_negative_check()},
      {"--lost-distance", &FollowParams::lost_distance_per_dim,
       "lost_distance_per_dim (all trackers; the HMM's ceiling)", non_negative_check()},
      {"--lost-residual", &FollowParams::lost_residual_per_dim,
       "lost_residual_per_dim: the HMM's lost distance on a noiseless sensor (all HMM variants; "
       "above --lost-distance, that fixed ceiling alone)",
       non_negative_check()},
      {"--lost-noise-factor", &FollowParams::lost_noise_factor,
       "lost_noise_factor: what the estimated sensor noise adds to the HMM's lost distance, per "
       "unit of noise (all HMM variants)",
       non_negative_check()},
      {"--lost-residual-factor", &FollowParams::lost_residual_factor,
       "lost_residual_factor: the HMM's lost distance is at least this times the average best "
       "distance of the frames it plainly follows (all HMM variants)",
       non_negative_check()},
      {"--lost-confirm-s", &FollowParams::lost_confirm_s,
       "lost_confirm_s: the input must stay past the HMM's noise-scaled lost distance on "
       "consecutive frames this long before it is called lost (all HMM variants)",
       number_between(0.0, 10.0, "s")},
      {"--found-confirm-per-lost", &FollowParams::found_confirm_per_lost_s,
       "found_confirm_per_lost_s: after a spell lost by distance, the input must stay within the "
       "lost distance this times the spell's length before it is followed again (at least "
       "--lost-confirm-s, at most --found-confirm-max-s; full body only, all HMM variants)",
       number_between(0.0, 10.0)},
      {"--found-confirm-max-s", &FollowParams::found_confirm_max_s,
       "found_confirm_max_s: the longest --found-confirm-per-lost asks for",
       number_between(0.0, 10.0, "s")},
      {"--held-place-lost-s", &FollowParams::held_place_lost_s,
       "held_place_lost_s: an estimate held within --held-place-reach-s of one place for longer "
       "than this is reported lost (input seconds; 0 for never; all HMM variants)",
       number_between(0.0, 600.0, "s")},
      {"--held-place-reach-s", &FollowParams::held_place_reach_s,
       "held_place_reach_s: how far (template seconds) the estimate must move to start a new "
       "hold",
       number_between(0.001, 10.0, "s")},
      {"--tempo-hold-window-s", &FollowParams::tempo_hold_window_s,
       "tempo_hold_window_s: a window of input this long whose estimate advances less than "
       "--tempo-hold-advance frames per frame of time is a hold, and teaches the tempo nothing (0 "
       "for every "
       "band move; all HMM variants but the paper preset)",
       number_between(0.0, 2.0, "s")},
      {"--tempo-hold-advance", &FollowParams::tempo_hold_advance,
       "tempo_hold_advance: template frames per template frame of input time under which a "
       "window is a hold",
       number_between(0.0, 1.99)},
      {"--tempo-hold-max-s", &FollowParams::tempo_hold_max_s,
       "tempo_hold_max_s: a hold longer than this is someone standing, and its moves teach the "
       "tempo again",
       number_between(0.0, 600.0, "s")},
      {"--found-still-spell-s", &FollowParams::found_still_spell_s,
       "found_still_spell_s: after a spell lost by distance this long or longer, the place found "
       "again is reported lost until the estimate moves on by --found-still-reach-s (input "
       "seconds; 0 for never; all HMM variants)",
       number_between(0.0, 600.0, "s")},
      {"--found-still-reach-s", &FollowParams::found_still_reach_s,
       "found_still_reach_s: how far (template seconds) the estimate must move from where it was "
       "found again",
       number_between(0.001, 10.0, "s")},
      {"--missing-lost-s", &FollowParams::missing_lost_s,
       "missing_lost_s: input without evidence (missing, or the sensor's last pose sent again) "
       "for longer than this is reported lost (input seconds; 0 for never; all HMM variants)",
       number_between(0.0, 600.0, "s")},
      {"--lost-velocity-cap-per-dim", &FollowParams::lost_velocity_cap_per_dim,
       "lost_velocity_cap_per_dim: most the velocity blocks add to the lost test's distance, per "
       "dimension of the model (and at most --velocity-cap; inf: the emission's); all HMM "
       "variants",
       cap_check()},
      {"--emission-noise-factor", &FollowParams::emission_noise_factor,
       "emission_noise_factor: what the estimated sensor noise adds to the emission's variance "
       "per dimension, per unit of noise (all HMM variants)",
       non_negative_check()},
      {"--emission-noise-allowance", &FollowParams::emission_noise_allowance,
       "emission_noise_allowance: estimated sensor noise that does not widen the emission (all "
       "HMM variants)",
       non_negative_check()},
      {"--noise-filter-allowance", &FollowParams::noise_filter_allowance,
       "noise_filter_allowance: estimated sensor noise that the input's smoothing lets through "
       "(all HMM variants)",
       non_negative_check()},
      {"--noise-filter-density", &FollowParams::noise_filter_density,
       "noise_filter_density: the dance's acceleration density the Kalman filter of the input's "
       "posture features assumes; lower smooths more, 0 for none (all HMM variants)",
       non_negative_check()},
      {"--pause-noise-factor", &FollowParams::pause_noise_factor,
       "pause_noise_factor: what the estimated sensor noise adds to the pause state's level, per "
       "unit of noise (all HMM variants)",
       non_negative_check()},
      {"--velocity-cap", &FollowParams::velocity_distance_cap,
       "velocity_distance_cap: most the velocity blocks add to a squared distance (all HMM "
       "variants; inf for none)",
       cap_check()},
      {"--limb-outlier-ratio", &FollowParams::limb_outlier_ratio,
       "limb_outlier_ratio: the farthest limb adds at most this times the second farthest to a "
       "squared distance (all HMM variants; inf for none)",
       cap_check()},
      {"--limb-outlier-floor", &FollowParams::limb_outlier_floor,
       "limb_outlier_floor: ... but never less than this (all HMM variants)", non_negative_check()},
      {"--outlier-pause-fraction", &FollowParams::outlier_pause_fraction,
       "outlier_pause_fraction: the outlier gate sets a frame aside only when its best distance "
       "is beyond this share of the pause level",
       non_negative_check()},
      {"--outlier-max-s", &FollowParams::outlier_max_s,
       "outlier_max_s: how long the outlier gate sets a run of outlier frames aside (input "
       "seconds; 0 for one frame only)",
       number_between(0.0, 10.0, "s")},
      {"--jump-hold", &FollowParams::jump_hold_s,
       "jump_hold_s: how long a far place must hold the posterior's maximum before it is "
       "reported as a jump (template seconds; 0 for at once)",
       number_between(0.0, 10.0, "s")},
      {"--noisy-jump-hold", &FollowParams::noisy_jump_hold_s,
       "noisy_jump_hold_s: the jump hold under a noisy sensor, reached at noisy_jump_hold_level "
       "of estimated noise (template seconds; 0 for none)",
       number_between(0.0, 10.0, "s")},
      {"--unexplained-jump-hold", &FollowParams::unexplained_jump_hold_s,
       "unexplained_jump_hold_s: the jump hold for a far place the input fits poorly, its best "
       "distance over --unexplained-jump-ratio x the sensor's noise and over the lost residual "
       "(template seconds; 0 for none)",
       number_between(0.0, 10.0, "s")},
      {"--unexplained-jump-ratio", &FollowParams::unexplained_jump_ratio,
       "unexplained_jump_ratio: see --unexplained-jump-hold", positive_check()},
      {"--unexplained-jump-hold-after", &FollowParams::unexplained_jump_hold_after_s,
       "unexplained_jump_hold_after_s: the unexplained jump hold applies only to a move from a "
       "place followed this long since the last reported jump (template seconds; 0 for every "
       "place)",
       number_between(0.0, 60.0, "s")},
      {"--jump-old-place-mass", &FollowParams::jump_old_place_mass,
       "jump_old_place_mass: a far place is reported only once the old place's reach holds at "
       "most this share of the posterior (1 for no such test)",
       number_between(0.0, 1.0)},
      {"--jump-alike-distance", &FollowParams::jump_alike_distance_per_dim,
       "jump_alike_distance_per_dim: a far move between places whose template rows are within "
       "this distance per dimension is no jump (0 for none)",
       non_negative_check()},
      {"--jump-settle", &FollowParams::jump_settle_s,
       "jump_settle_s: after the start, moves of the estimate are the first placement being "
       "refined, not jumps, until it has held one place this long (template seconds; 0 for "
       "none)",
       number_between(0.0, 10.0, "s")},
      {"--jump-settle-mass", &FollowParams::jump_settle_mass,
       "jump_settle_mass: only frames with at least this window mass count towards settling the "
       "first placement (0 for every frame)",
       number_between(0.0, 1.0)},
      {"--jump-settle-advance", &FollowParams::jump_settle_advance_s,
       "jump_settle_advance_s: ... and only once the estimate has also moved forward through its "
       "take this far (template seconds; 0 for none): a standing start looks like every take's "
       "standing moments",
       number_between(0.0, 10.0, "s")},
      {"--jump-burst", &FollowParams::jump_burst_s,
       "jump_burst_s: a jump that would be the --jump-burst-jumps-th reported within this time "
       "is not reported and the placement starts again (template seconds)",
       number_between(0.0, 60.0, "s")},
      {"--jump-catch-up", &FollowParams::jump_catch_up_s,
       "jump_catch_up_s: a far move forward within the take ending at most this far past the "
       "band's reach is a catch-up, not a jump (template seconds; 0 for none)",
       number_between(0.0, 10.0, "s")},
  };
  return rows;
}

}  // namespace

FollowTuning::FollowTuning() : floats_(float_rows().size()) {}

void FollowTuning::add_options(CLI::Option_group& group) {
  const std::vector<FloatRow>& rows = float_rows();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    group.add_option(rows[i].flag, floats_[i], rows[i].help)->check(rows[i].check);
  }
  group
      .add_option("--jump-tolerance", jump_tolerance_,
                  "jump_tolerance_frames: a move back by up to this many frames is no jump")
      ->check(CLI::Range(0, 1000));
  group
      .add_option("--jump-burst-jumps", jump_burst_jumps_,
                  "jump_burst_jumps: see --jump-burst (0 for no such limit)")
      ->check(CLI::Range(0, FollowParams::kMaxJumpBurstJumps));
  group
      .add_option("--tempo-time-constant", tempo_time_constant_,
                  "tempo_time_constant_s of the tempo-centred band (all HMM variants)")
      ->check(positive_check());
  group.add_flag("--fixed-band", fixed_band_,
                 "Keep the band fixed at the template's tempo (tempo_adaptive = false)");
  group.add_flag("--no-outlier-gate", no_outlier_gate_,
                 "gate_outliers = false: a frame that would hand the pause state the majority "
                 "right after a followed frame is evidence like any other");
  group.add_flag("--pause-reported-lost", pause_reported_lost_,
                 "pause_reported_lost: report frames whose posterior the pause state holds as "
                 "lost although a template frame explains them (the paper preset's reading; all "
                 "HMM variants)");
}

void FollowTuning::apply(FollowParams& params) const {
  const std::vector<FloatRow>& rows = float_rows();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (floats_[i]) params.*rows[i].field = *floats_[i];
  }
  if (jump_tolerance_) params.jump_tolerance_frames = *jump_tolerance_;
  if (jump_burst_jumps_) params.jump_burst_jumps = *jump_burst_jumps_;
  if (tempo_time_constant_) params.tempo_time_constant_s = *tempo_time_constant_;
  if (fixed_band_) params.tempo_adaptive = false;
  if (no_outlier_gate_) params.gate_outliers = false;
  if (pause_reported_lost_) params.pause_reported_lost = true;
}

}  // namespace duet::app
