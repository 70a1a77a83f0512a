// Where in the response clip the partner is shown, as a real frame (method.md 5.3 smoothness,
// applied to time). The follower's estimate is a whole template frame that advances by 0, 1 or
// 2 frames per input frame, so for a dancer at 0.7x the template's tempo the raw estimate holds
// and steps (0, 1, 1, 2, 3, 3, ...): the partner moves in a staircase, which shows as jerk
// (docs/evaluation.md, partner metrics). The playhead instead advances at the tempo the follower
// measured (FollowResult::tempo) and is pulled towards the estimate (with its place between
// frames, FollowResult::frame_offset: a real frame) with a half-life, never further than
// max_offset_frames from it; at a jump, a change of take or the first frame it
// starts on the estimate. The pose is then sampled at that real frame (Clip::sample).
#pragma once

#include "duet/partner/jitter_meter.h"

namespace duet {

// Chosen with `duet eval` (docs/evaluation.md, partner metrics): half-life / max offset 0.05 s /
// 1 frame, 0.1 / 1, 0.03 / 0.5, 0.1 / 2, 0.2 / 2 gave joint jerk 1031, 997, 1133, 977, 951 m/s^3
// on `tempo-slow` (1883 without the playhead) but post-jump spikes the true response does not
// have on `improv-30hz-noisy` 2, 2, 0, 1, 0 of 24 and hand-relation medians 0.52, 0.57, 0.49,
// 0.60, 0.71 cm on `improv-pause`: 0.03 s / 0.5 frame stays closest to the estimate.
struct PlayheadParams {
  double pull_half_life_s = 0.03;  // how fast a difference to the estimate is closed
  double max_offset_frames = 0.5;  // the playhead stays within this of the estimate
  // Under a noisy sensor the estimate jitters by frames, and within half a frame of it the
  // partner's whole body jitters along (issue 11: at 4 degrees per axis the partner's p99 joint
  // speed was 1.34x the captured, most of it the hips in turns). The playhead measures that
  // jitter (from the estimate's second differences, over jitter_time_constant_s) and widens its
  // band to jitter_offset_factor times its RMS (at most max_jitter_offset_frames), with the
  // half-life grown in proportion, so it rides through the jitter; on a steady, a slowly
  // changing or a paused estimate the band stays max_offset_frames. 0: no widening. Measured in
  // docs/evaluation.md ("Partner steadiness", factors 1-3).
  double jitter_offset_factor = 3.0;
  double max_jitter_offset_frames = 3.0;
  double jitter_time_constant_s = 1.0;
  // Once the follower has been lost this long (seconds) the partner dances on by itself from
  // where it was, at the dancer's last tempo, instead of following an estimate that wanders
  // between look-alike places (PartnerPlace; docs/partner.md "While the follower is lost").
  // Shorter spells, such as the landing of a jump, are followed as they come. 0: from the first
  // lost frame; inf: never.
  double coast_after_lost_s = 0.1;
  // A move of the estimate further than this (template frames) from where the dancer's tempo
  // takes it, which the follower does not call a jump (a catch-up of up to 2n + 6 frames, a
  // correction while lost or settling), restarts the playhead there with a blend (PartnerPlace)
  // instead of being played at several times the tempo. Measured in docs/evaluation.md
  // ("Catch-ups are blended"): 3 / 4 / 6 / 8 frames; inf: only another take and the follower's
  // own jumps.
  double blend_beyond_frames = 4.0;
  // Empty when valid, else which value is wrong.
  const char* validate() const noexcept;
};

class ResponsePlayhead {
 public:
  // A new performance: also forgets the measured jitter (a jump keeps it: it is the sensor's).
  void reset() noexcept {
    primed_ = false;
    jitter_.reset();
  }
  // estimate: the follower's frame (plus its place between frames); restart: a jump or another take
  // (start on the estimate); tempo: template frames per template frame of input time (non-finite or
  // <= 0: 1); dt_s: time since the previous call (<= 0 or non-finite: restart); frame_rate: the
  // template's. Returns the real frame to show, within max_offset_frames of the estimate (the
  // caller clamps it to the clip).
  double advance(double estimate, bool restart, double tempo, double dt_s, double frame_rate,
                 const PlayheadParams& params) noexcept;
  double position() const noexcept { return position_; }
  // The estimate's jitter RMS (frames) the band is widened by.
  double jitter_frames() const noexcept { return jitter_.rms(); }

 private:
  bool primed_ = false;
  double position_ = 0.0;
  JitterMeter jitter_;  // of the estimate, in frames
};

}  // namespace duet
