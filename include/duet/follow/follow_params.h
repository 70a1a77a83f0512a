// Parameters of the follower HMM (method.md 4). Plain named fields; the defaults were chosen by
// measurement with `duet eval` (method.md 7, docs/evaluation.md), the `paper` preset reproduces
// [4.2].
#pragma once

#include <algorithm>
#include <vector>

#include "duet/base/result.h"
#include "duet/follow/tempo_band.h"

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

  // Tempo-centred band (include/duet/follow/tempo_band.h): each frame the band above is tilted so
  // that its mean advance equals the tempo the dancer has shown, estimated from the follower's
  // own band moves with this time constant and clamped to [min_tempo, max_tempo]. false keeps the
  // band fixed (the paper's model, and the `paper` preset).
  // 2 s: long enough that a pause or a jump's first frames barely move it, short enough to follow
  // a drifting tempo (improvisation with pauses: 98.8% within 100 ms at 1 s, 99.9% at 2 s).
  bool tempo_adaptive = true;
  double tempo_time_constant_s = 2.0;
  float min_tempo = 0.4f;
  float max_tempo = 1.8f;
  // A dancer holding a pose is no tempo: the band's self moves through a hold taught the estimate
  // a slower dancer (0.5 s of hold at 2 s memory: 1.0 -> 0.87), and after the next jump the
  // estimate drifted behind the truth through a standing stance the emission cannot place (up to
  // 12 frames). So the moves of a window of tempo_hold_window_s of input time whose net advance is
  // under tempo_hold_advance template frames per template frame of time are undone, for holds up
  // to tempo_hold_max_s (longer, someone standing: the Bandai dance as three points stands for
  // 8.5 s and was 92.4 % lost without the limit, 96.9 with 1 s). `harsh` 96.84 -> 97.68 %,
  // `improv-pause` 99.01 -> 99.99 (docs/evaluation.md, "A hold is no tempo"). Window 0: every
  // band move counts.
  float tempo_hold_window_s = 0.25f;
  float tempo_hold_advance = 0.3f;
  float tempo_hold_max_s = 1.0f;

  // Pause state N (eq. 6): stay N->N with pause_stay_prob (A_NN), resume N->i with
  // (1 - A_NN) * R_i. R is uniform over the template states when resume_weights is empty,
  // otherwise resume_weights[i] (M non-negative weights, normalised at set-up).
  float pause_stay_prob = 0.90f;
  std::vector<float> resume_weights;

  // false gives the left-to-right HMM baseline: no pause state, no jump, and at the end of a
  // take the remaining band probabilities are renormalised (the last frame becomes absorbing).
  bool jump_enabled = true;

  // Emission (eq. 7): b_i(phi) = exp(-||phi - phi_i||^2 / (2 sigma^2)), in the units of the
  // standardised, weighted features (with the velocity cap below). sigma sets how much one frame's
  // evidence weighs against the band's prior: too large and the estimate lags behind tempo
  // changes (the prior wins), too small and noise makes it jitter and jump. Chosen by `duet eval`
  // on the 14 salsa duets (docs/evaluation.md): two random template frames are about 2.5 apart
  // (squared) and frames 0.1 s apart about 0.25; 0.7 let the prior win (78.6% within 100 ms at
  // 1.4x tempo), 0.15 gave >= 97.5% in every case, and with the velocity cap and the
  // tempo-centred band 0.1 gives >= 98.8%.
  float emission_sigma = 0.10f;

  // Robust emission: the squared distance over the model's velocity dimensions
  // (TemplateModel::velocity_dims) counts at most this much. Velocities are differences over a
  // window of input frames, so a tracking glitch, or a dancer who switched to another part of the
  // dance, corrupts them for the whole window (0.1 s) while the posture is already right; the cap
  // lets the posture decide then. 0.05 is the squared distance between template frames about
  // 50 ms apart: velocities still separate look-alike postures, but never outvote them. In
  // `duet eval` it took improvisation from 98.7% to 99.8% of frames within 100 ms and noisy input
  // from 99.2% to 100% (docs/evaluation.md). +inf gives the plain Gaussian of eq. 7.
  float velocity_distance_cap = 0.05f;

  // Robust emission, by limb: the limb (TemplateModel::limbs: an arm's two bone directions and
  // its hand's place, a leg's likewise) whose squared distance is the largest counts at most
  // limb_outlier_ratio times the second largest's, and never less than limb_outlier_floor. An
  // optical system loses an arm's markers whenever the partner's body hides them, and its solver
  // holds the arm where it was last seen: the held arm outweighs the rest of the body, and a
  // place elsewhere whose arm happens to be where the held one is fits better (`duet eval` case
  // `occluded`: 2.0-2.4 false jumps a minute). One limb far out of line with the others is what
  // a held limb looks like; noise, a suit's calibration error and a wrong place move every limb.
  // A cap on each limb's share instead (0.1) cost 2-5 points at 4-5 degrees of noise and 5-9 on
  // `suit-drift`. The floor keeps a gesture the library does not hold from passing for a dance:
  // at 0.05 the Bandai wave was lost on 90 % of its frames (96.7 % unbounded), at 0.15 96.7 %.
  // Only the emission is bounded: FollowResult::best_distance_per_dim, the lost test and what
  // scales with them count every limb. docs/evaluation.md, "One limb out of line". +inf: no
  // bound (the paper's plain Gaussian).
  float limb_outlier_ratio = 3.0f;
  float limb_outlier_floor = 0.15f;

  // The pause state's emission is flat: the likelihood of a template frame at this mean squared
  // distance per dimension, i.e. b_N = exp(-pause_distance_per_dim * D / (2 sigma^2)). The pause
  // state (and through it the jump) wins when every reachable frame is farther than that. Keep
  // pause_distance_per_dim * D / (2 sigma^2) near 25 when changing sigma: larger and the pause
  // state's mass rounds to zero, so no jump is ever taken.
  float pause_distance_per_dim = 0.009f;

  // Lost: no template frame is within this mean squared distance per dimension of the input, or
  // the pause state holds most of the posterior mass. The baselines use it as it is; the HMM
  // takes the smaller of it and the noise-scaled level below (it is then only a ceiling).
  float lost_distance_per_dim = 0.05f;

  // Scaled to the sensor's noise (issue 11). The follower estimates the input's white-noise
  // variance per posture dimension online (sensor_noise.h, over this time constant) and
  //  - raises the pause state's level by pause_noise_factor times what of it exceeds
  //    pause_noise_allowance (the fixed level was chosen at 3 degrees RMS, noise 0.0015, and
  //    allows for about that: raised from 0 on, noise@asf lost 0.3 points): noise adds to every
  //    template distance alike, so without it a sensor with 4 degrees per axis put every frame
  //    past the pause level (the pause state won: 30% of the followed frames lost, 887 false
  //    jumps a minute);
  //  - calls a frame lost when its best template distance per dimension exceeds
  //    lost_residual_per_dim + lost_noise_factor * noise: what a clean dance never reaches
  //    (0.0011 at most on the 14 cases) plus what the sensor's noise adds (the best distance is
  //    about 0.8 x the noise estimate, 2.8 x at its 99.5th percentile). A clean walk, a wave or
  //    another dance stays far above it. Measured in docs/follower.md.
  //  - takes the larger of that and lost_residual_factor times the average best distance of the
  //    frames it plainly follows (explained_residual.h): another rig leaves a residual of its own
  //    (on the CMU handshake rig up to 4% of the followed frames were lost without it).
  //  - widens the emission (eq. 7): its variance per dimension is emission_sigma^2 (the
  //    template's own spread) plus emission_noise_factor times what of the noise exceeds
  //    emission_noise_allowance, what the sensor adds to every dimension of the input. Noise
  //    makes the differences between template distances noisy, and an emission sharpened for a
  //    clean sensor turns each noisy frame into strong, wrong evidence: the maximum flickers to
  //    look-alike places. At 4 degrees per axis (noise about 0.009) the emission's variance
  //    goes from 0.01 to 0.034: 30hz-noisy went from 93.2% to 99.4% within 100 ms and from 136
  //    to 8.4 false jumps a minute. sigma was chosen with 3 degrees RMS of noise, which reads
  //    0.0015 on the library's rig and up to 0.002 on others; widened from 0.001 on, 30hz-noisy
  //    on the handshake rig lost 1.5 points and noise on the ASF rig 2.6, so the allowance is
  //    0.003 (input with up to 3 degrees is unchanged on every rig).
  // lost_residual_per_dim = +inf and pause_noise_factor = emission_noise_factor = 0 give the
  // fixed levels (paper).
  double sensor_noise_time_constant_s = 1.0;
  float pause_noise_factor = 3.0f;
  float pause_noise_allowance = 0.001f;
  float lost_residual_per_dim = 0.0015f;
  float lost_noise_factor = 3.5f;
  float lost_residual_factor = 5.0f;
  // The noise-scaled lost distance calls the input lost only once it has been passed on
  // consecutive frames for this long (input time): one frame past it is a sensor's flicker, not
  // a dance the library does not hold. A headset's 1 degree of head-turn noise makes the head's
  // yaw rate, one velocity dimension of thirteen, pass it alone on single frames (the estimated
  // noise is an average over the posture dimensions): three points flagged 1.7 % of the frames
  // of a clean take lost, nearly all on their own. 0 calls every such frame lost.
  float lost_confirm_s = 0.05f;
  // Followed again after a spell lost by distance: within the lost distance on consecutive frames
  // for found_confirm_per_lost_s times the spell's time past it, at most found_confirm_max_s (and
  // at least lost_confirm_s; found_confirm_s()). Motion no part of the library holds passes through
  // poses that a dance holds too: a wave's arm coming down is a salsa take's standing start. Half
  // a minute of the Bandai wave was followed on 6.4 % of its frames, in runs of 1-27 frames
  // between seconds lost (93.6 % lost, under issue 11's 95); a dancer found again after a spell
  // holds the dance. 0: lost_confirm_s after any spell. Three points take 0
  // (follow_params_for): their input is lost and found again often within a dance, and waiting
  // doubled their improvised cases' frames lost although followed (docs/evaluation.md, "Found
  // again after a spell lost"). 0.5 s at most until session 48: with the hands' speeds on a
  // standard arm (FeatureSpec::standard_arm_speeds) the looped wave was 94.3 % lost at 0.5, 97.4 at
  // 0.75 (97.2 before), 99.6 at 1.5 (docs/evaluation.md, "A hand's speed on a standard arm").
  float found_confirm_per_lost_s = 0.25f;
  float found_confirm_max_s = 0.75f;
  double found_confirm_s(double lost_spell_s) const noexcept {
    const double grown = std::min(static_cast<double>(found_confirm_per_lost_s) * lost_spell_s,
                                  static_cast<double>(found_confirm_max_s));
    return std::max(grown, static_cast<double>(lost_confirm_s));
  }
  // The lost test counts the velocity blocks at most this much per dimension of the model (and
  // at most velocity_distance_cap), at the estimated state. The emission's cap is one number for
  // any model: over the full body's 50 dimensions velocities alone can never pass the lost
  // distance, over three points' 13 they could, and a dance 1.4x faster than its take did
  // (three points' `tempo-fast`: 3.6 % of its tracked frames lost; docs/evaluation.md "Lost on
  // three points' velocities"). 0.0019 caps three points' at 0.025, half the emission's, and
  // leaves the full body's as it was; a walk, whose velocities differ most, stays lost.
  float lost_velocity_cap_per_dim = 0.0019f;
  // Whether a pause-state majority is reported lost (FollowResult::lost) although a template
  // frame explains the input within the lost distance: the follower between places after a jump,
  // still deciding where the user went. true is the paper preset's reading; by default lost says
  // only that no part of the library explains the input (the jump gate and the tempo band still
  // treat such frames as lost). Reported lost, they were most of three points' lost frames on
  // tracked dance: `improv-30hz-noisy` 5.0 -> 3.0 %, `harsh` 4.6 -> 3.6 %, walk still 99.5 %.
  bool pause_reported_lost = false;
  // An estimate held within held_place_reach_s of template time of one place for longer than
  // held_place_lost_s of input time is reported lost (HeldPlace): a dance moves on, and a
  // person standing still matches a take's standing start but is no part of the dance. The
  // improvised cases hold a pose for at most 0.8 s, the takes' standing starts pass in ~1 s. The
  // Bandai dance as three points, 85.5 % lost without: 2 / 3 / 4 / 5 s: 96.9 / 95.3 / 93.6 /
  // 92.2 %; 3 s leaves room for a dancer's own pause (docs/evaluation.md, "A place held too
  // long"). 0: never.
  float held_place_lost_s = 3.0f;
  float held_place_reach_s = 0.2f;
  // After a spell lost by distance of found_still_spell_s of input time or longer, the place the
  // follower finds again is reported lost (FollowResult::still_since_lost) until the estimate
  // moves found_still_reach_s of template time from where the found-again wait began
  // (StillSinceFound): a wave's arm coming down
  // leaves a person standing as a take's standing start does, and a dancer found again moves on
  // with the dance. The Bandai wave as three points was 75.2 % lost (issue 11: >= 95), its second
  // between two waves followed on one standing frame; 96.7 % with 0.3 or 0.5 s and a reach of
  // 0.05, 0.1 or 0.2 s. Three points' dance frames lost on tracked rose 0.93 -> 0.99 % at 0.5 /
  // 0.1 against 1.03 at 0.3 / 0.1 and 1.10 at 0.3 / 0.2; the full body's were the same (its found
  // again waits, found_confirm_per_lost_s). 0: never (docs/evaluation.md, "Still where found
  // again").
  float found_still_spell_s = 0.5f;
  float found_still_reach_s = 0.1f;
  // A frame without evidence (FollowResult::missing: no usable pose, or the sensor sent its last
  // pose again) moves the band on at the dancer's tempo and keeps the last frame's lost flag and
  // confidence: the tempo carries the estimate through a stall of seconds (`duet eval`'s `stalls`,
  // docs/evaluation.md "A sensor that stalls"). Past missing_lost_s of input time in a row
  // without evidence it is reported lost, with no confidence: nothing says where the dancer is
  // (a headset taken off, a stream that stopped). 0: never.
  float missing_lost_s = 3.0f;
  float emission_noise_factor = 4.0f;
  float emission_noise_allowance = 0.003f;
  // Smoothing of the input's posture features by the noise (noise_filter.h): the spectral
  // density of the dance's acceleration that its Kalman filter assumes, in standardised feature
  // units^2 / s^3 (lower smooths more; 0, the default, turns it off), and the noise it lets
  // through unfiltered. Off because it did not hold up (docs/follower.md): at 4 degrees per axis
  // density 1000 took false jumps down on some performances and up on others, cost `noise` 3
  // points on two seeds of four, and made beam mode fall 0.6 points behind the exact step at
  // 30 Hz. Kept for experiments (`duet eval --noise-filter-density`).
  float noise_filter_density = 0.0f;
  float noise_filter_allowance = 0.004f;

  // Confidence: posterior mass within +/- this many template frames of the estimate (same take),
  // mapped to the probability of being within 100 ms (confidence_calibration.h) when
  // calibrate_confidence; false reports the mass itself (paper).
  int confidence_window_frames = 6;
  bool calibrate_confidence = true;

  // Jump decisions (JumpGate, issue 11). A move of the estimate back by up to
  // jump_tolerance_frames is jitter, not a jump: counting it took 67 false jumps a minute at 3
  // degrees of sensor noise to 0.6. A move out of the band's reach is reported only once the new
  // place has held the posterior's maximum for jump_hold_s of template time. Measured in
  // docs/follower.md: a hold of 0.05-0.1 s removed no further false jump and cost up to 2 points
  // at 4 degrees of noise (a wrong place held on while the maximum moved between others), so it
  // is off by default. 0 and 0: every move of the maximum out of the band is a jump (paper).
  float jump_hold_s = 0.0f;
  // Under a noisy sensor the maximum makes one-frame excursions to a look-alike place and back
  // (two false jumps each). The hold then grows with the estimated sensor noise: from 0 at half
  // noisy_jump_hold_level to noisy_jump_hold_s at it and above (the larger of this and
  // jump_hold_s applies). About 1.5 and 3.5 degrees per axis; on a clean sensor jumps are taken
  // at once. Measured in docs/follower.md ("Jump decisions").
  float noisy_jump_hold_s = 0.04f;
  float noisy_jump_hold_level = 0.006f;
  // A far place the input fits poorly holds the maximum for unexplained_jump_hold_s before it is
  // a jump (the larger hold applies): its best distance per dimension is over
  // unexplained_jump_ratio times the sensor's noise and over lost_residual_per_dim. An arm that an
  // optical system holds where it last saw it (the partner's body hides its markers; the
  // `occluded` case) fits another take's pose better for a moment than its own, at 2.4-4.2 times
  // the noise; a true jump's new place fits the input as well as any frame does (0.3-2.8 times
  // the noise on `improv-30hz-noisy` and `harsh`), so only a few true jumps wait. Measured in
  // docs/evaluation.md ("An arm held where last seen"). 0: no such hold.
  float unexplained_jump_hold_s = 0.4f;
  float unexplained_jump_ratio = 2.2f;
  // ... only once the place left has been followed for unexplained_jump_hold_after_s (template
  // time) since the last reported jump or the first placement. A place just landed on is still
  // being refined (a jump's landing corrected to the true place); a look-alike that takes the
  // maximum from a place followed for seconds is what the hold is for. Three points on the CMU
  // handshake rig make such excursions (3-9 false jumps a minute): held 0.3 s from every place
  // they lost 0.5-1.0 points on `improv` on the ASF and handshake rigs, from places followed 2 s
  // nothing (follow_params_for); the full body's figures are the same to the digit with 0 or 2.
  // docs/evaluation.md, "Three points hold a look-alike". 0: from every place.
  float unexplained_jump_hold_after_s = 2.0f;
  // A far place is reported only once the old place has lost its evidence too (with or without
  // a hold): the posterior mass within the old place's reach (the band of the frame, plus
  // jump_tolerance_frames back) is at most this share. A look-alike place that briefly takes
  // the maximum leaves the old place much of its mass (median 0.06 on false jumps at 4 degrees
  // per axis), a real jump next to none (0.000, 90th percentile 0.003). 1: no such test. Until
  // session 9 it applied only while a hold did (docs/follower.md, "Jump decisions").
  float jump_old_place_mass = 0.05f;
  // A far move between two places that look alike is no jump: the template rows of the old and
  // the new place are within this mean squared standardised distance per dimension (the same
  // unit as FollowResult::best_distance_per_dim). Every take starts and ends with its dancers
  // standing; under noise or on another rig the maximum moves between those standing frames
  // (0.0006-0.004 apart), which accounted for 24 of the 30 false jumps left over 3 seeds of the
  // 5-rig table and the 4-degree sweep, against 33 of 820 reported jumps that answered a true
  // one (nearly all a landing on one look-alike corrected to another). The estimate still moves
  // there; the partner blends at a change of take all the same (LiveLoop). 0: none.
  float jump_alike_distance_per_dim = 0.004f;
  int jump_tolerance_frames = 6;
  // The first placement: after a start (or reset) the estimate's first moves are the follower
  // finding where the dancer is, not the dancer jumping. Until the estimate has stayed within
  // reach of its place from frame to frame for jump_settle_s (template time), a far move takes
  // the new place without reporting a jump. 0: every far move is a jump from the first frame on.
  // 0.3 s (0.1 before session 6): at 4 degrees per axis the first placement can sit on a
  // look-alike for a few frames at a time for seconds (`improv-30hz-noisy` seed 3: 8.4 -> 1.1
  // false jumps a minute); docs/follower.md, "Jump decisions".
  float jump_settle_s = 0.3f;
  // ... counting only frames the follower is sure of (window mass at least jump_settle_mass):
  // under noise the first placement often sits on a look-alike place of another take with a
  // window mass of 0.6-0.97 before the maximum moves on. 0: every frame within reach counts.
  float jump_settle_mass = 0.99f;
  // ... and only once the estimate has also moved forward through its take for
  // jump_settle_advance_s (template time from where it began to the furthest it has reached, on
  // frames within reach it is sure of; jitter back and forth moves it nowhere): a dancer found is
  // a dancer followed while moving. Every take begins with its dancers standing,
  // and a standing start looks like every standing moment of every take: under an inertial
  // suit's calibration error the estimate sat on another take's standing frame, sure of it, for
  // seconds, then moved between such places, each move a reported jump (`suit-drift`, takes 2, 4,
  // 9, 11: 4.3-7.1 false jumps a minute, all but one in the first 10 s; 0.2-1.1 with 0.5 s, as
  // with 1 or 2 s; docs/evaluation.md, "A placement found while moving"). 0: time alone settles.
  float jump_settle_advance_s = 0.5f;
  // A burst of jumps is a place lost, not a dancer jumping: a reported jump that would be the
  // jump_burst_jumps-th within jump_burst_s (template time) is not reported, and the placement
  // starts again as at the start (jump_settle_s, jump_settle_mass, jump_settle_advance_s), so the
  // moves that find the dancer again are no jumps either. Three points on another rig without a
  // calibration, having lost the place, hopped between takes every 0.1-0.5 s for seconds (a
  // 0.8x body on the CMU ASF rig: 43 jumps reported in 12 s of one take, none true); improvised
  // jumps come seconds apart, a landing corrected to the true place one after it.
  // docs/evaluation.md, "A burst of jumps is a place lost". 0 jumps: no such limit.
  int jump_burst_jumps = 3;
  float jump_burst_s = 2.0f;
  static constexpr int kMaxJumpBurstJumps = 8;
  // A catch-up is no jump: a far move forward within the estimate's take that ends at most
  // jump_catch_up_s (template time) past the band's reach (TemplateModel::is_jump over the steps
  // since the place it leaves) is the follower catching up with a dancer it lagged (its tempo
  // behind the dancer's, or a hold that kept the old place while the maximum ran ahead), not the
  // dancer leaving their figure: the estimate moves there, the partner blends to it as to any far
  // move (PartnerPlace), and FollowResult::jumped stays false. Improvised jumps go to another
  // part of the dance. Three points on the CMU handshake rig: 14 of 42 false jumps (every take,
  // seed 1). docs/evaluation.md, "A catch-up is no jump". 0: every far move can be a jump.
  float jump_catch_up_s = 0.5f;
  // Outlier gate: a frame whose evidence would hand the pause state the majority right after a
  // frame that was followed (the first placement settled, that frame not lost) is taken for an
  // outlier of the sensor: its evidence is set aside (transitions only, as for a dropped frame).
  // Such frames in a row are set aside for outlier_max_s of input time; the next is evidence
  // again: the dancer really jumped, paused or left the library. Without it one outlier frame at 4
  // degrees per axis moved the posterior to the pause state and from there to a look-alike place
  // and back (two false jumps); innovation gating, as in a Kalman filter's measurement gate.
  bool gate_outliers = true;
  // ... only when nothing explains the frame well either: its best distance is beyond this share
  // of the pause state's level (NoiseScaledLevels::pause_distance_sq). Where the follower merely
  // sat on the wrong place, or the dancer jumped, the pause state takes the majority too, but the
  // right place explains the frame: measured over 6 seeds at 4 degrees per axis, frames with
  // the pause majority after a followed frame had a best distance of at most 0.4 of the pause
  // level at true jumps (434 of 437), at least 0.6 without one (73 of 74).
  float outlier_pause_fraction = 0.5f;
  // How long a run of outlier frames is set aside (input seconds; 0: one frame only, as until
  // session 52). A tracker's pop lasts a frame or a few (a marker swap, a flipped limb): with one
  // frame set aside, the second put the pause state in the majority and the estimate on another
  // take for a frame, where the partner went and came back (`glitches`: a planted foot sliding at
  // 11.6 m/s). Three points keep 0 (follow_params_for). docs/evaluation.md, "A sensor that pops".
  float outlier_max_s = 0.1f;

  // Input at another rate: each input frame applies n = clamp(round(dt_s * template_fps), 1,
  // max_steps_per_frame) template-rate transitions before its emission. The cap also bounds a
  // tracking loss: after a gap the dancer has danced on, and a band that could not follow them
  // (8 steps, 0.13 s at 60 Hz) left them to the pause state, a reported jump at every loss of
  // 0.3-1 s (the `dropouts` case: 4.5-7.3 false jumps a minute, 0 with 120). A frame after a
  // 2 s gap then costs 120 band transitions (docs/follower.md, "Tracking losses").
  int max_steps_per_frame = 120;

  // The paper's hand-set values [4.2]: self = next = 0.33, leave = resume = 0.165 (resume is
  // 1 - A_NN, so A_NN = 0.835). The paper gives no skip probability: skip = 0. Rows are
  // normalised, so out of a template state self = next = 0.4 and leave = 0.2. The band is fixed
  // (tempo_adaptive = false), as in the paper.
  static FollowParams paper();
  // The left-to-right HMM baseline: these defaults with jump_enabled = false.
  static FollowParams left_to_right();

  // Checks ranges and finiteness; num_states is M (for the size of resume_weights).
  Status validate(int num_states) const;

  // The tempo estimate's limits (tempo_band.h) for a template at template_fps.
  TempoLimits tempo_limits(double template_fps) const;
};

}  // namespace duet
