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
// tempo across jumps (the music does not change) and a hold does not drag it to zero.
// How the estimate moves: its memory (the step response reaches 63% after time_constant_s of
// input) and the range it is clamped to.
struct TempoLimits {
  double time_constant_s = 1.0;
  float min_tempo = 0.4f;
  float max_tempo = 1.8f;
};

class TempoEstimator {
 public:
  void reset() noexcept {
    tempo_ = 1.0f;
    updates_ = 0;
    mean_steps_ = 0.0;
    mean_template_frames_ = 0.0;
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
  // The dancer's tempo in template frames per template frame of input time (1 = the template's
  // tempo) at any sensor rate: tempo() times the steps applied per template frame of input time
  // (averages over the estimate's memory). What the partner's playhead and `/duet/tempo` need.
  float dancer_tempo() const noexcept;

 private:
  float tempo_ = 1.0f;
  int updates_ = 0;  // band moves seen since reset, for the start-up average
  // Averages of the steps applied per frame and of the template frames of input time per frame
  // (observe_rate); their ratio is 1 at the template's rate or slower.
  double mean_steps_ = 0.0;
  double mean_template_frames_ = 0.0;
};

}  // namespace duet
