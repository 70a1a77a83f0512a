// Online removal of a rig's constant posture offset (issue 10).
//
// Two rigs never put their joints at quite the same places: the CMU ASF skeleton's shoulders are
// 44 cm apart where the salsa BVH's are 23 cm, its head joint sits 4 cm higher, and a rig
// retargeted by copying local rotations bends its arms differently to reach the same hands. In the
// canonical body space those differences are a near-constant offset of the posture features, which
// on take 01 delivered on the ASF rig was larger than the gap between frames 100 ms apart: the
// follower read the same dance as another one. The offset is estimated online as a slow average of
// the residual between the (corrected) input and the template frame the follower has confidently
// matched, and subtracted from later inputs, like cepstral mean normalisation in speech. On the
// library's own rig the residual averages to about zero, so nothing changes there.
//
// Under a noisy sensor the average is itself noisy, and an offset of noise-level size made things
// worse, not better: at 4 degrees per axis the follower with no offset at all was up to 2.9 points
// closer to the truth on `noise` (docs/evaluation.md, "Results", session 8). So the offset applied
// is the average shrunk by its own uncertainty, the sensor's white-noise variance (estimated
// online by the tracker) over the average's effective number of frames: a rig's real offset, many
// standard errors from zero, is applied whole; noise-sized averages are not applied at all.
#pragma once

#include <span>
#include <vector>

#include "duet/features/offset_search.h"

namespace duet {

struct PostureBiasParams {
  bool enabled = true;
  // The average's time constant (seconds of confident frames): time_constant_s on a steady
  // sensor, longer as the sensor's white noise rises, as the square root of the noise (the
  // steady-state gain of a Kalman filter for a level that wanders, sqrt(wander / noise)), up to
  // noisy_time_constant_s at noisy_time_constant_level. Session 10 shortened it from 4 to 2 s to
  // follow an inertial suit's drift (the shrinkage below keeps the white noise out). Session 31:
  // at 1 s throughout a suit 8 + 8 degrees off was followed 67.2 -> 73.9 % within 100 ms
  // (`--suit-sweep`, 28 performances), but `noise-sweep-4` (4 degrees per axis, a noise of about
  // 0.008) lost 0.06-0.25 points on five rigs; a suit's 3 degrees of white noise is about 0.002.
  // docs/evaluation.md, "An offset found while lost".
  double time_constant_s = 1.0;
  double noisy_time_constant_s = 2.0;
  float noisy_time_constant_level = 0.008f;
  // Three points (a headset and two controllers) keep 2 s throughout: there the shorter average
  // gained nothing on the suit and cost `improv-30hz-noisy` 0.8-1.4 points on the Bandai and
  // proportioned rigs. FollowSession uses it as time_constant_s for a three-point input.
  double head_hands_time_constant_s = 2.0;
  double min_weight = 0.2;       // a frame's weight is the follower's confidence, at least this
  float max_offset = 2.0f;       // per dimension, in standardised units (a runaway guard)
  // Frames whose best template match is further than this (squared standardised distance per
  // dimension, as FollowResult::best_distance_per_dim) teach nothing. Learning from every frame
  // let a walk's offset make it look like salsa (the Bandai walk went from 98 % lost to 69 %);
  // measured in docs/features.md. On a steady sensor a frame this far is the offset itself (an
  // inertial suit's calibration and drift reach 0.005-0.014); as the sensor's white noise rises
  // to noisy_learn_level the limit falls to max_learn_distance_noisy_per_dim, since there the
  // larger distances are noise and a match a frame or two off (docs/evaluation.md, "Results",
  // session 10). 0.01 until session 23: a suit whose standing start taught the offset against
  // another frame then put every frame of take 60_10's first steps at 0.010-0.014, where none
  // could teach (69 % within 100 ms, 48 false jumps a minute; docs/evaluation.md, "A suit's
  // offset learnt from further frames"). The walk stays lost: the pause state holds it. 0.02
  // until session 32: a suit 8 degrees off per joint in calibration and drift put whole dances
  // past it (`--suit-sweep`, suit-sweep-8 73.9 / 62.7 % within 100 ms on the library's / ASF
  // rig; 0.03: 76.7 / 75.7, 0.04: 79.9 / 78.6); every other case and the non-dance clips the
  // same to 0.05 points (docs/evaluation.md, "A suit's offset learnt from further frames, again").
  float max_learn_distance_per_dim = 0.03f;
  float max_learn_distance_noisy_per_dim = 0.005f;
  float noisy_learn_level =
      0.004f;  // sensor noise per dimension (FollowResult::sensor_noise_per_dim)
  // The limit never falls below this many times the sensor's own noise: at 4 degrees per axis a
  // right match's best distance is about the noise itself (median 0.0066 at a noise of 0.0082 on
  // `harsh@asf`), so a fixed 0.005 kept most frames of a noisy sensor from teaching a rig's
  // offset. Only sensors above about 3.3 degrees per axis reach the floor; 1 / 1.5 / 2 / 3 swept
  // in docs/evaluation.md ("A noisy sensor's frames teach the offset", session 29). 0: no floor.
  float learn_noise_factor = 2.0f;
  // The limit above for a sensor whose white-noise variance per dimension is sensor_noise.
  float learn_distance_limit(float sensor_noise) const noexcept;
  // The average's time constant for that sensor.
  double time_constant(float sensor_noise) const noexcept;
  // Per dimension the applied offset is mean * max(0, 1 - (k se / mean)^2), se^2 the variance
  // of the running mean given the sensor's noise (James-Stein-like positive-part shrinkage).
  // 2 / 3 / 4 / 6 swept in docs/evaluation.md ("Results", session 8); 0 applies the mean as learnt.
  double shrink_k = 4.0;
  // An offset held through release_after_lost_s seconds of lost frames in a row is let go
  // (reset()), to be learnt again. Learnt against another take's standing start, a suit's or a
  // far rig's offset can leave every later frame too far from the library to teach it, and the
  // follower lost for the rest of the dance (`suit-drift@asf` of take 60_09, seed 1: 90 % of
  // frames lost, 41 % within 100 ms; docs/evaluation.md, "Letting a lost offset go"). Offsets
  // under release_offset_rms (root mean square over the dimensions; the library's own rig stays
  // under 0.001) are kept. 0: never let go.
  double release_after_lost_s = 4.0;
  float release_offset_rms = 0.01f;
  // ... lost in a row: a run is broken only by release_found_s of frames followed in a row. Three
  // points' lost flag flickers back for a frame or two (they keep FollowParams::lost_confirm_s
  // after any spell), and each flicker started the count again: an offset that left three points
  // on the handshake rig lost on 27 % of the frames they followed was never let go
  // (`improv-30hz-noisy@handshake`, 64.8 % within 100 ms; 79.6 % with 0.25 s; docs/evaluation.md,
  // "Three points let a lost offset go"). 0: any frame followed breaks the run.
  double release_found_s = 0.25;
  // FollowSession maps the tracker's confidence through YoungOffsetConfidence while the offset is
  // young (young_offset_confidence.h): at a standing start on another rig the follower matched
  // another take's stance at 0.9+ confidence and was right on 30-60 % of those frames.
  bool young_offset_confidence = true;
  // ... and then a lost frame's confidence through LostConfidence (lost_confidence.h): three
  // points on another rig claimed 0.9 and more on lost frames right 42-56 % of the time.
  bool lost_confidence = true;
  // While the pause state holds the input, FollowSession looks for an offset beyond the learning
  // gate (offset_search.h): a suit calibrated 8 degrees off per joint was lost for 15 s.
  OffsetSearchParams search;
};

class PostureBias {
 public:
  PostureBias() = default;
  // Dimensions [begin, begin + size) of the standardised feature vector are adapted.
  PostureBias(int begin, int size, const PostureBiasParams& params);

  // Subtracts the current offset from the posture dimensions. Allocates nothing.
  void correct(std::span<float> features) const noexcept;
  // Learns from one frame: `corrected` is what correct() returned, `matched` the template row the
  // follower settled on, dt_s the time since the previous frame, sensor_noise the input's
  // white-noise variance per posture dimension (FollowResult::sensor_noise_per_dim; 0 for a
  // clean sensor). Non-finite input is ignored.
  void learn(std::span<const float> corrected, std::span<const float> matched, double dt_s,
             float confidence, float sensor_noise = 0.0f) noexcept;
  void reset() noexcept;
  // Takes on an offset found while lost (OffsetSearch), on top of the one held, as if learnt over
  // `seconds`; the lost run starts again.
  void adopt(std::span<const float> offset, double seconds) noexcept;
  // One frame's lost flag (FollowResult::lost) dt_s after the previous frame: lets the offset go
  // after PostureBiasParams::release_after_lost_s lost in a row (broken only by release_found_s
  // followed). Allocates nothing.
  void note_lost(bool lost, double dt_s) noexcept;

  // What correct() subtracts: the running mean, shrunk by its uncertainty.
  std::span<const float> offset() const noexcept { return offset_; }
  // The running mean of input - matched template itself.
  std::span<const float> mean() const noexcept { return mean_; }
  // The offset's root mean square over the dimensions, and the confident seconds it has been
  // learnt from since reset() (each frame weighted by the follower's confidence, at least
  // min_weight).
  float offset_rms() const noexcept { return offset_rms_; }
  double learnt_s() const noexcept { return learnt_s_; }
  const PostureBiasParams& params() const noexcept { return params_; }

 private:
  int begin_ = 0;
  PostureBiasParams params_;
  std::vector<float> mean_;    // running mean of input - matched template, per dimension
  std::vector<float> offset_;  // mean_ shrunk by its uncertainty (params_.shrink_k)
  float offset_rms_ = 0.0f;    // of offset_
  double learnt_s_ = 0.0;      // weighted seconds learnt since reset
  double lost_s_ = 0.0;        // seconds lost in a row (note_lost)
  double found_s_ = 0.0;       // seconds followed in a row since (note_lost)
};

}  // namespace duet
