// The band's tempo (method.md 4, eq. 4): the self/next/skip probabilities tilted so that their
// mean advance per template-rate step equals the dancer's current tempo, and the estimator of that
// tempo from the follower's own decisions.
//
// Why: with a fixed band the prior's mean advance is one template frame per step. Where the
// template barely changes from frame to frame (a held pose, a slow turn) the emission cannot
// tell neighbouring frames apart, so the estimate drifts at the prior's tempo: ahead of a 0.7x
// dancer, behind a 1.4x one (docs/evaluation.md, finding 1). Centering the band on the tempo the
// dancer has shown over the last second removes that bias without weakening the band.
#pragma once

#include <array>

namespace duet {

// Probabilities of moving 0, 1 or 2 template frames in one template-rate step; they sum to the
// band's share of the row (1 - leave).
struct BandProbabilities {
  float self = 0.0f;
  float next = 0.0f;
  float skip = 0.0f;

  float total() const { return self + next + skip; }
  // Mean advance per step, in template frames.
  float mean_advance() const;
};

// The distribution closest to `base` (least Kullback-Leibler divergence) whose mean advance is
// `tempo`: p_d proportional to base_d * x^d. The mean condition is a quadratic in x,
//   base.skip (2 - tempo) x^2 + base.next (1 - tempo) x - tempo base.self = 0,
// solved in closed form; the total mass is kept. Tempo outside what the band's support can reach
// (>= 2 with a skip, >= 1 without, <= 0) is clamped just inside it; base.self == 0 or an
// unreachable tempo returns base unchanged.
BandProbabilities tilt_band(const BandProbabilities& base, float tempo);

// Exponentially weighted estimate of the dancer's tempo (template frames per template-rate step,
// 1 = the template's own tempo) from consecutive decisions. Only band moves count: a frame that
// jumped, paused, was lost or missing leaves the estimate as it was, so a dancer keeps their
// tempo across jumps (the music does not change) and a pause does not drag it to zero; nor does a
// hold the follower reads as the band's self moves (hold_window_s below).
// How the estimate moves: its memory (the step response reaches 63% after time_constant_s of
// input) and the range it is clamped to: min_tempo is the slowest dancer's tempo (per template
// frame of input time: per step it falls on a sensor faster than the template, 0.1 at 240 Hz);
// max_tempo is per step, what the band reaches (under 2).
struct TempoLimits {
  double time_constant_s = 1.0;
  float min_tempo = 0.4f;
  float max_tempo = 1.8f;
  // A dancer holding a pose is no tempo. Every band move is taught at once, but a window of
  // hold_window_s of input (decided frames only; a jump, lost or missing frame ends it and judges
  // it if half as long) whose estimate advances less than hold_advance template frames per
  // template frame of input time (template_fps; 0: per step) is a hold, and its moves are undone.
  // 0: no window, every band move stands. A hold longer than hold_max_s is someone standing, not
  // a dancer's hold: from then on its moves stand.
  double hold_window_s = 0.0;
  float hold_advance = 0.3f;
  double template_fps = 0.0;
  double hold_max_s = 1.0;
};

class TempoEstimator {
 public:
  void reset() noexcept {
    tempo_ = 1.0f;
    updates_ = 0;
    pending_first_ = 0;
    pending_count_ = 0;
    pending_s_ = 0.0;
    pending_moved_ = 0;
    pending_frames_ = 0.0;
    held_s_ = 0.0;
    mean_steps_ = 1.0;
    mean_template_frames_ = 1.0;
    rate_frames_ = kRatePriorFrames;
  }
  // One decision: the estimate moved from previous_state to state in `steps` template-rate steps
  // over dt_s seconds of input; usable is false for frames that must not count (see above).
  void update(int previous_state, int state, int steps, double dt_s, bool usable,
              const TempoLimits& limits) noexcept;
  float tempo() const noexcept { return tempo_; }

  // Every frame: it applied `steps` transitions for dt_s seconds of input (dt_s * template_fps
  // template frames). A sensor faster than the template applies one step per frame however short
  // the frame, so tempo() counts per step, not per template frame of time: at 240 Hz on a 60 Hz
  // template a dancer at the template's tempo moves 0.25 frames a step. Ignores a first frame
  // (dt_s 0) and non-finite input.
  void observe_rate(int steps, double dt_s, double template_fps,
                    const TempoLimits& limits) noexcept;
  // Until a move is taught: tempo() becomes the template's own tempo in steps at the rate
  // observe_rate has seen (0.5 at 120 Hz on a 60 Hz template). Called after observe_rate by a
  // follower whose band follows the tempo.
  void start_at_template_tempo(const TempoLimits& limits) noexcept;
  // The dancer's tempo in template frames per template frame of input time (1 = the template's
  // tempo) at any sensor rate: tempo() times the steps applied per template frame of input time
  // (averages over the estimate's memory). What the partner's playhead and `/duet/tempo` need.
  float dancer_tempo() const noexcept;

 private:
  // A decided move still inside the window (TempoLimits::hold_window_s), taught already.
  struct PendingMove {
    int moved = 0;
    double dt_s = 0.0;
    double template_frames = 0.0;  // of input time
    bool within_reach = false;     // within the band's reach either way: counted in the net advance
    float tempo_before = 1.0f;     // the estimate before this move was taught, to undo it
    int updates_before = 0;
  };
  // Sensors up to 240 Hz fill a quarter of a second; beyond, the oldest move stands early.
  static constexpr int kMaxPending = 64;

  void teach(int moved, int steps, double dt_s, const TempoLimits& limits) noexcept;
  // Whether the window's net advance is under hold_advance frames a step.
  bool is_hold(const TempoLimits& limits) const noexcept;
  // Ends the window: with `judge`, a hold's moves are undone; otherwise they stand.
  void settle_window(bool judge, const TempoLimits& limits) noexcept;
  // Drops the oldest move from the window: it stands.
  void forget_oldest() noexcept;
  // Steps applied per template frame of input time (observe_rate); 1 at the template's rate or
  // slower.
  double steps_per_template_frame() const noexcept;

  float tempo_ = 1.0f;
  int updates_ = 0;  // band moves seen since reset, for the start-up average
  // Averages of the steps applied per frame and of the template frames of input time per frame
  // (observe_rate); their ratio is 1 at the template's rate or slower. They start from a prior
  // of kRatePriorFrames frames at the template's rate: a sensor's first frames may come bunched
  // (0.1 ms apart, one step each), and read alone they made a 60 Hz stream a 10 kHz one.
  static constexpr int kRatePriorFrames = 4;
  double mean_steps_ = 1.0;
  double mean_template_frames_ = 1.0;
  int rate_frames_ = kRatePriorFrames;  // frames averaged, the prior's included
  // Pending moves, a ring: the oldest at pending_first_; their input time, net advance and steps.
  std::array<PendingMove, kMaxPending> pending_{};
  int pending_first_ = 0;
  int pending_count_ = 0;
  double pending_s_ = 0.0;
  int pending_moved_ = 0;
  double pending_frames_ = 0.0;
  double held_s_ = 0.0;  // input time of the hold so far (windows judged holds in a row)
};

}  // namespace duet
