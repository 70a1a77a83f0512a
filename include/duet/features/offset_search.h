// Finding a rig's posture offset while nothing in the library explains the input (issues 10 and
// 11: a suit calibrated badly).
//
// PostureBias learns a rig's offset only from frames the library already explains (within its
// learning gate), so that a walk cannot teach the offset that would make it look like salsa. An
// offset larger than the gate therefore never starts: an inertial suit off by 8 degrees of
// calibration per joint put every frame of take 60_14 at 0.010-0.022 per dimension from the
// library, the pause state held it, and the follower was lost for the first 15 s (58 % within
// 100 ms; docs/evaluation.md, "An offset found while lost"). Yet the tracker's best place among
// the template frames was often right all along: the dance is there, shifted.
//
// This search tries that: while the pause state holds the input, it keeps a trial offset, the
// running mean of the posture residual against the template frame the tracker rates best. The
// trial is adopted once, for hold_s of frames that follow one another as a dance does (same take,
// moving forward within the band), the input with it removed would have been explained: the
// running mean of the distance per dimension to the matched frame (posture less the trial as
// learnt before that frame, the velocity blocks as they are, which an offset hardly moves) stays
// within the learning gate; and the matched frames moved meanwhile (min_motion_per_dim). A walk
// matched against salsa keeps no one residual, so it stays lost; a stance explains any offset
// (the Bandai dance's first second matched a salsa standing start at an offset of 0.14 RMS and
// was then followed on 12 % of its frames), hence the motion. docs/evaluation.md, "An offset
// found while lost". Allocation-free after construction.
#pragma once

#include <span>
#include <vector>

namespace duet {

struct OffsetSearchParams {
  bool enabled = true;
  // The trial offset's time constant (a running mean while younger), and how long the input,
  // with the trial removed, must have been explained along an unbroken path before it is adopted.
  double time_constant_s = 1.0;
  double hold_s = 1.0;
  // The least the matched template frames must have moved over the trial (running mean of their
  // posture's squared distance from its running mean, per dimension of the whole vector). Suits 8
  // degrees off, adopted along the dance: 0.0077-0.011; the Bandai dance's stance 0.0007, its
  // first steps 0.0030 (followed on 8 % of its frames after); one suit's near-stance 0.0031.
  double min_motion_per_dim = 0.005;
};

class OffsetSearch {
 public:
  OffsetSearch() = default;
  // Dimensions [posture_begin, posture_begin + posture_size) of a standardised feature vector of
  // `dimension` dimensions are the posture block; the rest are left as they are.
  OffsetSearch(int posture_begin, int posture_size, int dimension);

  // One frame the pause state holds: `input` the (already corrected) features, `matched` the
  // template row the tracker rates best, `continues` whether that row follows the previous
  // frame's as the dance does, `limit` the learning gate (squared distance per dimension, as
  // PostureBiasParams::learn_distance_limit). Returns true when the trial has held for hold_s and
  // the matched frames moved enough: offset() is then the posture offset to remove on top of the
  // one already removed.
  // Non-finite input counts for nothing.
  bool observe(std::span<const float> input, std::span<const float> matched, bool continues,
               float limit, double dt_s, const OffsetSearchParams& params) noexcept;
  void reset() noexcept;

  std::span<const float> offset() const noexcept { return mean_; }
  double held_s() const noexcept { return held_s_; }
  double explained() const noexcept { return explained_; }
  double motion() const noexcept { return motion_; }

 private:
  int posture_begin_ = 0;
  int dimension_ = 0;
  std::vector<float> mean_;          // running mean of input - matched over the posture block
  std::vector<float> matched_mean_;  // running mean of the matched rows' posture
  double motion_ = 0.0;     // running mean of their squared distance from it, per dimension
  double seen_s_ = 0.0;     // seconds observed since reset()
  double held_s_ = 0.0;     // seconds the path has been explained with the trial removed
  double explained_ = 0.0;  // running mean of that distance per dimension
};

}  // namespace duet
