// The tempo-centred band (tempo_band.h): the tilt reaches the asked mean and stays a valid band;
// the estimator learns a steady tempo, ignores what is not a band move and keeps its range.
#include "duet/follow/tempo_band.h"

#include <gtest/gtest.h>

#include <cmath>

namespace duet {
namespace {

constexpr BandProbabilities kDefaultBand{0.30f, 0.35f, 0.30f};  // FollowParams{} without leave

TEST(TiltBand, ReachesTheTempoAndKeepsTheTotal) {
  for (const float tempo : {0.4f, 0.7f, 1.0f, 1.3f, 1.8f}) {
    SCOPED_TRACE(tempo);
    const BandProbabilities band = tilt_band(kDefaultBand, tempo);
    EXPECT_NEAR(band.mean_advance(), tempo, 1e-4f);
    EXPECT_NEAR(band.total(), kDefaultBand.total(), 1e-6f);
    EXPECT_GT(band.self, 0.0f);
    EXPECT_GT(band.next, 0.0f);
    EXPECT_GT(band.skip, 0.0f);
  }
}

TEST(TiltBand, IsTheIdentityAtTheBandsOwnMean) {
  const BandProbabilities band = tilt_band(kDefaultBand, kDefaultBand.mean_advance());
  EXPECT_NEAR(band.self, kDefaultBand.self, 1e-6f);
  EXPECT_NEAR(band.next, kDefaultBand.next, 1e-6f);
  EXPECT_NEAR(band.skip, kDefaultBand.skip, 1e-6f);
}

TEST(TiltBand, SlowerTempoMovesMassTowardsSelf) {
  const BandProbabilities slow = tilt_band(kDefaultBand, 0.7f);
  const BandProbabilities fast = tilt_band(kDefaultBand, 1.4f);
  EXPECT_GT(slow.self, kDefaultBand.self);
  EXPECT_LT(slow.skip, kDefaultBand.skip);
  EXPECT_LT(fast.self, kDefaultBand.self);
  EXPECT_GT(fast.skip, kDefaultBand.skip);
}

TEST(TiltBand, ClampsUnreachableTempiAndRejectsDegenerateBands) {
  // A mean of 2 needs all mass on skip: clamped just inside, still finite and positive.
  const BandProbabilities fastest = tilt_band(kDefaultBand, 5.0f);
  EXPECT_TRUE(std::isfinite(fastest.self) && fastest.self > 0.0f);
  EXPECT_NEAR(fastest.mean_advance(), 1.98f, 1e-3f);
  const BandProbabilities stopped = tilt_band(kDefaultBand, -1.0f);
  EXPECT_NEAR(stopped.mean_advance(), 0.02f, 1e-3f);
  // Without a skip the band can only reach means below 1.
  const BandProbabilities no_skip = tilt_band({0.4f, 0.4f, 0.0f}, 1.5f);
  EXPECT_NEAR(no_skip.mean_advance(), 0.99f, 1e-3f);
  EXPECT_EQ(no_skip.skip, 0.0f);
  // Nothing to tilt: returned as it is, also for a NaN tempo.
  const BandProbabilities only_self = tilt_band({0.5f, 0.0f, 0.0f}, 1.0f);
  EXPECT_EQ(only_self.self, 0.5f);
  const BandProbabilities nan_tempo = tilt_band(kDefaultBand, std::nanf(""));
  EXPECT_EQ(nan_tempo.next, kDefaultBand.next);
}

TEST(TempoEstimator, LearnsASteadyTempo) {
  TempoEstimator estimator;
  const TempoLimits limits;  // 2 s memory
  // A dancer at 1.5x: 3 frames every 2 steps, in alternation 1 and 2.
  int state = 100;
  for (int t = 0; t < 600; ++t) {
    const int moved = t % 2 == 0 ? 1 : 2;
    estimator.update(state, state + moved, 1, 1.0 / 60, true, limits);
    state += moved;
  }
  EXPECT_NEAR(estimator.tempo(), 1.5f, 0.02f);
  // A 30 Hz input (two steps per frame) at 0.7x.
  estimator.reset();
  EXPECT_EQ(estimator.tempo(), 1.0f);
  double position = 0.0;
  for (int t = 0; t < 300; ++t) {
    const int before = static_cast<int>(position);
    position += 1.4;
    estimator.update(before, static_cast<int>(position), 2, 1.0 / 30, true, limits);
  }
  EXPECT_NEAR(estimator.tempo(), 0.7f, 0.02f);
}

TEST(TempoEstimator, IgnoresJumpsPausesAndBackwardMoves) {
  TempoEstimator estimator;
  const TempoLimits limits;
  for (int t = 0; t < 200; ++t) estimator.update(t, t + 1, 1, 1.0 / 60, true, limits);
  const float learned = estimator.tempo();
  EXPECT_NEAR(learned, 1.0f, 1e-3f);
  estimator.update(50, 900, 1, 1.0 / 60, true, limits);   // a jump forward
  estimator.update(900, 20, 1, 1.0 / 60, true, limits);   // a jump back
  estimator.update(20, 20, 1, 1.0 / 60, false, limits);   // a pause frame
  estimator.update(-1, 20, 1, 1.0 / 60, true, limits);    // first frame: no previous state
  estimator.update(20, 21, 1, std::nan(""), true, limits);  // broken timestamp
  EXPECT_EQ(estimator.tempo(), learned);
}

TEST(TempoEstimator, ReportsTheDancersTempoAtAnySensorRate) {
  const TempoLimits limits;
  // 120 Hz on a 60 Hz template: one step per frame, a dancer at the template's tempo moves one
  // template frame every other frame, 0.5 per step. The dancer's tempo is 1.
  TempoEstimator fast;
  int state = 100;
  for (int t = 0; t < 1200; ++t) {
    const int moved = t % 2;
    fast.update(state, state + moved, 1, 1.0 / 120, true, limits);
    fast.observe_rate(1, 1.0 / 120, 60.0, limits);
    state += moved;
  }
  EXPECT_NEAR(fast.tempo(), 0.5f, 0.02f);
  EXPECT_NEAR(fast.dancer_tempo(), 1.0f, 0.04f);
  // Before any move is taught the estimate is the template's tempo at the sensor's rate.
  TempoEstimator untaught;
  for (int t = 0; t < 1200; ++t) {
    untaught.observe_rate(1, 1.0 / 120, 60.0, limits);
    untaught.start_at_template_tempo(limits);
  }
  EXPECT_NEAR(untaught.tempo(), 0.5f, 1e-3f);
  EXPECT_NEAR(untaught.dancer_tempo(), 1.0f, 1e-3f);
  // 240 Hz, four steps a template frame of time: the range bounds the dancer's tempo, not a
  // step's (a step's 0.4 held every dancer at 1.6x or faster). A learner at 0.7x moves 0.175 a
  // step.
  TempoEstimator at_240_hz, untaught_240_hz;
  double position = 100.0;
  state = 100;
  for (int t = 0; t < 2400; ++t) {
    position += 0.175;
    const int next = static_cast<int>(position);
    at_240_hz.observe_rate(1, 1.0 / 240, 60.0, limits);
    at_240_hz.update(state, next, 1, 1.0 / 240, true, limits);
    state = next;
    untaught_240_hz.observe_rate(1, 1.0 / 240, 60.0, limits);
    untaught_240_hz.start_at_template_tempo(limits);
  }
  EXPECT_NEAR(at_240_hz.dancer_tempo(), 0.7f, 0.04f);
  EXPECT_NEAR(untaught_240_hz.tempo(), 0.25f, 1e-3f);
  EXPECT_NEAR(untaught_240_hz.dancer_tempo(), 1.0f, 1e-3f);
  // A 60 Hz stream whose second frame comes 0.1 ms after the first (frames bunched by the
  // network): one step for 0.006 template frames of time. Read alone it was a 10 kHz sensor:
  // the reported tempo 166x, and the range a step may take shrunk to nothing.
  TempoEstimator bunched;
  bunched.observe_rate(1, 0.0001, 60.0, limits);
  bunched.start_at_template_tempo(limits);
  EXPECT_GT(bunched.tempo(), 0.7f);
  EXPECT_LT(bunched.dancer_tempo(), 1.01f);
  for (int t = 0; t < 120; ++t) {
    bunched.update(t, t + 1, 1, 1.0 / 60, true, limits);
    bunched.observe_rate(1, 1.0 / 60, 60.0, limits);
  }
  EXPECT_NEAR(bunched.tempo(), 1.0f, 0.02f);
  EXPECT_NEAR(bunched.dancer_tempo(), 1.0f, 0.02f);
  // 30 Hz (two steps a frame) and 60 Hz with late and early frames: a step is a template frame.
  TempoEstimator slow, jittered;
  for (int t = 0; t < 300; ++t) {
    slow.update(t * 2, t * 2 + 2, 2, 1.0 / 30, true, limits);
    slow.observe_rate(2, 1.0 / 30, 60.0, limits);
    const double dt = t % 2 == 0 ? 1.4 / 60 : 0.6 / 60;  // late, then the early one after it
    jittered.update(t, t + 1, 1, dt, true, limits);
    jittered.observe_rate(1, dt, 60.0, limits);
  }
  EXPECT_FLOAT_EQ(slow.dancer_tempo(), slow.tempo());
  EXPECT_NEAR(jittered.dancer_tempo(), jittered.tempo(), 0.02f);
  // Bad timing teaches nothing; reset forgets the rate.
  const float before = fast.dancer_tempo();
  fast.observe_rate(1, std::nan(""), 60.0, limits);
  fast.observe_rate(1, 0.0, 60.0, limits);
  EXPECT_EQ(fast.dancer_tempo(), before);
  fast.reset();
  EXPECT_EQ(fast.dancer_tempo(), 1.0f);
}

// A dancer at the template's tempo, 30 Hz (two steps a frame), `frames` frames from `state`.
int dance(TempoEstimator& estimator, int state, int frames, const TempoLimits& limits) {
  for (int t = 0; t < frames; ++t) {
    estimator.update(state, state + 2, 2, 1.0 / 30, true, limits);
    state += 2;
  }
  return state;
}

TEST(TempoEstimator, AHeldPoseTeachesNoTempo) {
  TempoLimits limits;
  limits.time_constant_s = 2.0;
  limits.hold_window_s = 0.25;
  limits.hold_advance = 0.3f;
  TempoEstimator estimator;
  int state = dance(estimator, 100, 120, limits);
  EXPECT_NEAR(estimator.tempo(), 1.0f, 1e-3f);
  // A hold of 0.6 s: the estimate stays, wobbles a frame back and on, as it does on a held pose.
  const int wobble[] = {0, 1, 0, -1, 0, 0, 1, 0, -1, 0};
  for (int t = 0; t < 18; ++t) {
    const int next = state + wobble[t % 10];
    estimator.update(state, next, 2, 1.0 / 30, true, limits);
    state = next;
  }
  // Whatever the window taught before the hold was seen is undone; at most the hold's last
  // quarter-second is still pending.
  EXPECT_GT(estimator.tempo(), 0.9f);
  state = dance(estimator, state, 60, limits);
  EXPECT_NEAR(estimator.tempo(), 1.0f, 0.02f);

  // Standing for 3 s is no dancer's hold: past hold_max_s (1 s) its moves stand.
  TempoEstimator standing;
  state = dance(standing, 100, 120, limits);
  for (int t = 0; t < 90; ++t) standing.update(state, state, 2, 1.0 / 30, true, limits);
  EXPECT_LT(standing.tempo(), 0.6f);

  // Without the window (0) the hold drags the estimate down, as before.
  TempoLimits every_move = limits;
  every_move.hold_window_s = 0.0;
  TempoEstimator dragged;
  state = dance(dragged, 100, 120, every_move);
  for (int t = 0; t < 18; ++t) dragged.update(state, state, 2, 1.0 / 30, true, every_move);
  EXPECT_LT(dragged.tempo(), 0.8f);
}

TEST(TempoEstimator, ASlowDancerIsNoHold) {
  TempoLimits limits;
  limits.time_constant_s = 2.0;
  limits.hold_window_s = 0.25;
  limits.hold_advance = 0.3f;
  // 0.45x at 60 Hz: 9 frames every 20 steps, in runs of zero and one moves.
  TempoEstimator estimator;
  int state = 100;
  double position = 100.0;
  for (int t = 0; t < 600; ++t) {
    position += 0.45;
    const int next = static_cast<int>(position);
    estimator.update(state, next, 1, 1.0 / 60, true, limits);
    state = next;
  }
  EXPECT_NEAR(estimator.tempo(), 0.45f, 0.02f);
  // A 120 Hz sensor makes a step a frame: a 0.5x dancer moves a quarter frame a step, under the
  // hold's 0.3, but half a template frame per template frame of time.
  TempoLimits fast_sensor = limits;
  fast_sensor.template_fps = 60.0;
  fast_sensor.min_tempo = 0.1f;  // the follower's 0.4 a step would clamp it
  TempoEstimator at_120_hz;
  int fast_state = 100;
  for (int t = 0; t < 1200; ++t) {
    const int next = 100 + (t + 1) / 4;
    at_120_hz.update(fast_state, next, 1, 1.0 / 120, true, fast_sensor);
    fast_state = next;
  }
  EXPECT_NEAR(at_120_hz.tempo(), 0.25f, 0.02f);
  // Jumps, lost and missing frames pass time but are neither taught nor a hold.
  const float learnt = estimator.tempo();
  for (int t = 0; t < 30; ++t) estimator.update(state, state + 500, 1, 1.0 / 60, false, limits);
  EXPECT_EQ(estimator.tempo(), learnt);
}

TEST(TempoEstimator, StaysInItsRange) {
  TempoEstimator estimator;
  const TempoLimits limits{0.5, 0.4f, 1.8f};
  for (int t = 0; t < 300; ++t) estimator.update(t, t, 1, 1.0 / 60, true, limits);  // frozen
  EXPECT_FLOAT_EQ(estimator.tempo(), 0.4f);
  for (int t = 0; t < 300; ++t) estimator.update(t, t + 2, 1, 1.0 / 60, true, limits);
  EXPECT_FLOAT_EQ(estimator.tempo(), 1.8f);
}

}  // namespace
}  // namespace duet
