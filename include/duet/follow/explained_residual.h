// How far the input sits from the library while the follower is plainly following it (issue 11).
//
// Another rig, another body or another dancer leaves a residual between a followed frame and its
// template frame that the sensor's white noise does not explain: on the CMU handshake rig the
// best distance per dimension of followed frames averaged 0.0004-0.0008 and reached 0.0024 for
// a second at a time, above the clean-sensor lost level (0.0015). This keeps a slow average of
// the best distance over frames that are part of an unbroken run of following (no jump, no
// pause, no missing frame for at least kRunS), so the lost level can scale with it. A walk never
// holds such a run for long (the estimate jumps or pauses), so it teaches nothing. A wave did:
// with the posture offset learnt against it, its estimate held one template frame for up to a
// second between jumps, unbroken, and taught the level up to the cap, and the wave looped for
// 30 s was then 81 % followed. A dancer moves through the template; so a run also teaches only
// while the estimate advances at a dancer's pace (an average of at least kMinAdvance template
// frames per template frame of input, over kAdvanceTimeConstantS).
#pragma once

namespace duet {

class ExplainedResidual {
 public:
  // The run an update must be part of before it teaches, in seconds of input.
  static constexpr double kRunS = 1.0;
  // The average's time constant (seconds of taught frames); it starts from 0.
  static constexpr double kTimeConstantS = 4.0;
  // The slowest average advance through the template (template frames per input time at the
  // template's rate) a run teaches at, and the time constant of that average.
  static constexpr double kMinAdvance = 0.5;
  static constexpr double kAdvanceTimeConstantS = 0.5;
  // A frame teaches at most this much (best distance per dimension): a runaway guard.
  static constexpr float kMaxResidual = 0.003f;

  void reset() noexcept;
  // One frame: its best distance per dimension, whether the follower followed it (not missing,
  // not in pause, not a jump), the template frames the estimate advanced since the previous
  // frame, the time since the previous frame (bad values: 1/60 s) and the template's frame rate.
  void update(float best_distance_per_dim, bool followed, int advanced_frames, double dt_s,
              double frame_rate_hz) noexcept;
  // The average best distance per dimension of taught frames; 0 until a frame has taught.
  float level() const noexcept { return static_cast<float>(level_); }

 private:
  double run_s_ = 0.0;
  double advance_ = 0.0;  // the run's average advance (template frames per template frame)
  double level_ = 0.0;
};

}  // namespace duet
