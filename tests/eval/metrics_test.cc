#include "duet/eval/metrics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace duet {
namespace {

constexpr double kFps = 60.0;

// A hand-made trace: n frames at 60 Hz in take 0, template frame = k.
struct Trace {
  std::vector<TruthFrame> truth;
  std::vector<double> times;
  std::vector<FrameEstimate> estimates;

  explicit Trace(int n) {
    for (int k = 0; k < n; ++k) {
      truth.push_back({0, static_cast<double>(k), false, false});
      times.push_back(k / kFps);
      estimates.push_back({0, k, false, false, 10.0});
    }
  }
  Metrics metrics(const MetricsOptions& options = {}) const {
    MetricsAccumulator a(options);
    a.add(truth, times, estimates, kFps);
    return a.summary();
  }
};

TEST(FrameError, IsTemplateTimeInMillisecondsAndMissesAreCapped) {
  const MetricsOptions options;
  EXPECT_DOUBLE_EQ(frame_error_ms({0, 100.0, false, false}, {0, 103}, kFps, options), 50.0);
  EXPECT_NEAR(frame_error_ms({0, 100.5, false, false}, {0, 100}, kFps, options), 8.333, 1e-3);
  EXPECT_DOUBLE_EQ(frame_error_ms({0, 100.0, false, false}, {1, 100}, kFps, options), 1000.0);
  EXPECT_DOUBLE_EQ(frame_error_ms({0, 100.0, false, false}, {-1, -1}, kFps, options), 1000.0);
  EXPECT_DOUBLE_EQ(frame_error_ms({0, 0.0, false, false}, {0, 600}, kFps, options), 1000.0);
  EXPECT_DOUBLE_EQ(frame_error_ms({0, 0.0, false, false}, {0, 600}, kFps, {2000.0, 100.0, 0.1}),
                   2000.0);
}

TEST(Metrics, PerfectFollowing) {
  const Metrics m = Trace(120).metrics();
  EXPECT_EQ(m.frames, 120);
  EXPECT_EQ(m.scored_frames, 120);
  EXPECT_DOUBLE_EQ(m.within_50ms, 1.0);
  EXPECT_DOUBLE_EQ(m.within_100ms, 1.0);
  EXPECT_DOUBLE_EQ(m.mean_error_ms, 0.0);
  EXPECT_DOUBLE_EQ(m.median_error_ms, 0.0);
  EXPECT_EQ(m.jumps, 0);
  EXPECT_DOUBLE_EQ(m.median_recovery_s, 0.0);
  EXPECT_DOUBLE_EQ(m.mean_step_us, 10.0);
}

TEST(Metrics, AccuracyThresholdsMeanMedianMissesAndLost) {
  Trace t(10);
  // Errors in frames: 0 0 0 3 (50 ms) 4 (66.7) 6 (100) 7 (116.7) 18 (300) wrong-take wrong-take.
  const int offsets[8] = {0, 0, 0, 3, 4, 6, 7, 18};
  for (int k = 0; k < 8; ++k)
    t.estimates[static_cast<std::size_t>(k)].frame_in_take = k + offsets[k];
  t.estimates[8].take = 1;
  t.estimates[9].take = -1;
  t.estimates[9].lost = true;
  const Metrics m = t.metrics();
  EXPECT_DOUBLE_EQ(m.within_50ms, 0.4);
  EXPECT_DOUBLE_EQ(m.within_100ms, 0.6);
  EXPECT_DOUBLE_EQ(m.within_300ms, 0.8);
  EXPECT_DOUBLE_EQ(m.miss_fraction, 0.2);
  EXPECT_DOUBLE_EQ(m.lost_fraction, 0.1);
  const double expected_mean =
      (0 + 0 + 0 + 50 + 400.0 / 6.0 + 100 + 700.0 / 6.0 + 300 + 1000 + 1000) / 10.0;
  EXPECT_NEAR(m.mean_error_ms, expected_mean, 1e-9);
  EXPECT_NEAR(m.median_error_ms, 0.5 * (400.0 / 6.0 + 100.0), 1e-9);
}

TEST(Metrics, PauseFramesAreNotScored) {
  Trace t(10);
  for (int k = 4; k < 8; ++k) {
    t.truth[static_cast<std::size_t>(k)].in_pause = true;
    t.estimates[static_cast<std::size_t>(k)].take = 3;  // anything goes while holding still
    t.estimates[static_cast<std::size_t>(k)].lost = true;
  }
  const Metrics m = t.metrics();
  EXPECT_EQ(m.frames, 10);
  EXPECT_EQ(m.pause_frames, 4);
  EXPECT_EQ(m.scored_frames, 6);
  EXPECT_DOUBLE_EQ(m.within_50ms, 1.0);
  EXPECT_DOUBLE_EQ(m.lost_fraction, 0.0);
}

TEST(Metrics, JumpRecoveryWaitsUntilTheEstimateStaysRight) {
  Trace t(120);
  // The dancer jumps at frame 30 to template frame 500 (and dances on from there).
  for (int k = 30; k < 120; ++k) t.truth[static_cast<std::size_t>(k)].template_frame = 470.0 + k;
  t.truth[30].jump = true;
  // The estimate keeps going the old way until frame 45, is right for two frames (45, 46), wrong
  // again, and right from frame 50 on.
  for (int k = 30; k < 120; ++k) {
    const bool right = (k >= 45 && k <= 46) || k >= 50;
    t.estimates[static_cast<std::size_t>(k)].frame_in_take = right ? 470 + k : k;
  }
  const Metrics m = t.metrics();
  EXPECT_EQ(m.jumps, 1);
  EXPECT_EQ(m.recovered_jumps, 1);
  EXPECT_NEAR(m.median_recovery_s, 20.0 / kFps, 1e-9);
  EXPECT_NEAR(m.mean_recovery_s, 20.0 / kFps, 1e-9);
  // A short hold accepts the two-frame visit? No: at least 3 frames are always required.
  MetricsOptions short_hold;
  short_hold.recovery_hold_s = 0.0;
  EXPECT_NEAR(t.metrics(short_hold).median_recovery_s, 20.0 / kFps, 1e-9);
  t.estimates[47].frame_in_take = 470 + 47;  // now 45..47 are right: three frames
  EXPECT_NEAR(t.metrics(short_hold).median_recovery_s, 15.0 / kFps, 1e-9);
  // Within 100 ms counts as recovered: an estimate 5 frames (83 ms) behind is fine.
  for (int k = 50; k < 120; ++k) t.estimates[static_cast<std::size_t>(k)].frame_in_take = 465 + k;
  EXPECT_NEAR(t.metrics().median_recovery_s, 20.0 / kFps, 1e-9);
}

TEST(Metrics, UnrecoveredJumpsAndRecoveryEndingAtThePause) {
  Trace t(200);
  // Jump at 20 (never recovered before the pause at 100-109), jump at 110 recovered at 116.
  for (int k = 20; k < 200; ++k) t.truth[static_cast<std::size_t>(k)].template_frame = 1000.0 + k;
  t.truth[20].jump = true;
  for (int k = 100; k < 110; ++k) t.truth[static_cast<std::size_t>(k)].in_pause = true;
  for (int k = 110; k < 200; ++k) t.truth[static_cast<std::size_t>(k)].template_frame = 300.0 + k;
  t.truth[110].jump = true;
  for (int k = 0; k < 200; ++k) {
    const double truth = t.truth[static_cast<std::size_t>(k)].template_frame;
    const bool right = k < 20 || k >= 116 || (k >= 96 && k < 110);  // 96..99: too short a hold
    t.estimates[static_cast<std::size_t>(k)].frame_in_take =
        right ? static_cast<int>(truth) : static_cast<int>(truth) + 100;
  }
  const Metrics m = t.metrics();
  EXPECT_EQ(m.jumps, 2);
  // The first jump is not recovered: 96..99 is right, but a hold of 0.1 s does not fit before the
  // pause. The second is recovered at 116, 0.1 s after the jump.
  EXPECT_EQ(m.recovered_jumps, 1);
  EXPECT_TRUE(std::isinf(m.median_recovery_s));  // half the jumps unrecovered
  EXPECT_NEAR(m.mean_recovery_s, 6.0 / kFps, 1e-9);
  // The pause frames are not scored even though the estimate is wrong there.
  EXPECT_EQ(m.scored_frames, 190);
}

TEST(Metrics, FalseJumpsAreReportedJumpsThatAnswerNoTrueJump) {
  // 60 s at 60 Hz; a true jump at frame 1800 after a 0.5 s pause (frames 1770-1799).
  Trace t(3600);
  for (int k = 1770; k < 1800; ++k) t.truth[static_cast<std::size_t>(k)].in_pause = true;
  t.truth[1800].jump = true;
  // Answers: at the pause's start (within the 0.1 s lead) and 0.9 s after the jump.
  t.estimates[1766].jumped = true;
  t.estimates[1854].jumped = true;
  // False: 0.2 s before the pause, 1.2 s after the jump, and one in the middle of nowhere.
  t.estimates[1758].jumped = true;
  t.estimates[1872].jumped = true;
  t.estimates[600].jumped = true;
  const Metrics m = t.metrics();
  EXPECT_EQ(m.reported_jumps, 5);
  EXPECT_EQ(m.false_jumps, 3);
  EXPECT_NEAR(m.false_jumps_per_minute, 3.0 / (3599.0 / 60.0 / 60.0), 1e-9);
}

TEST(Metrics, LostOnTrackedFramesCountsOnlyFramesWithin100Ms) {
  Trace t(100);
  for (int k = 0; k < 10; ++k) t.estimates[static_cast<std::size_t>(k)].lost = true;  // tracked
  for (int k = 50; k < 70; ++k) {
    t.estimates[static_cast<std::size_t>(k)] = {1, 0, true, false, 10.0};  // wrong take, lost
  }
  const Metrics m = t.metrics();
  EXPECT_NEAR(m.lost_fraction, 30.0 / 100.0, 1e-12);
  EXPECT_NEAR(m.lost_on_tracked_fraction, 10.0 / 80.0, 1e-12);
}

TEST(Metrics, LostSwitchesCountEveryChangeOfTheFlagPerMinute) {
  Trace t(601);  // 10 s at 60 Hz
  for (int k : {100, 200, 201, 202, 300}) t.estimates[static_cast<std::size_t>(k)].lost = true;
  // 100 on and off, 200-202 on and off, 300 on and off: 6 changes in 10 s.
  EXPECT_NEAR(t.metrics().lost_switches_per_minute, 36.0, 1e-9);
  Trace steady(601);
  for (int k = 100; k < 601; ++k) steady.estimates[static_cast<std::size_t>(k)].lost = true;
  EXPECT_NEAR(steady.metrics().lost_switches_per_minute, 6.0, 1e-9);
}

TEST(Metrics, PoolsPerformances) {
  Trace a(100), b(300);
  for (auto& e : b.estimates) e.take = 2;  // b is all misses
  MetricsAccumulator pooled;
  pooled.add(a.truth, a.times, a.estimates, kFps);
  MetricsAccumulator other;
  other.add(b.truth, b.times, b.estimates, kFps);
  pooled.merge(other);
  const Metrics m = pooled.summary();
  EXPECT_EQ(m.frames, 400);
  EXPECT_DOUBLE_EQ(m.within_100ms, 0.25);
  EXPECT_DOUBLE_EQ(m.mean_error_ms, 750.0);
  EXPECT_DOUBLE_EQ(m.median_error_ms, 1000.0);
}

TEST(Metrics, TheDanceIsFoundWhereTheEstimateFirstStaysRightForASecond) {
  Trace t(240);
  // A standing start guessed in another take for half a second, one frame right in it, then
  // right with a single slip at frame 50: the hold from 30 breaks there, so the dance is found
  // at frame 51. The pause frames 100-129 (anything goes) neither break nor count.
  for (int k = 0; k < 30; ++k) t.estimates[static_cast<std::size_t>(k)].take = 4;
  t.estimates[12].take = 0;
  t.estimates[50].frame_in_take += 12;  // 200 ms off
  for (int k = 100; k < 130; ++k) {
    t.truth[static_cast<std::size_t>(k)].in_pause = true;
    t.estimates[static_cast<std::size_t>(k)].take = 4;
  }
  t.estimates[200].take = 4;  // a later miss counts against the dance once found
  const Metrics m = t.metrics();
  EXPECT_NEAR(m.median_find_s, 51.0 / kFps, 1e-12);
  EXPECT_NEAR(m.worst_find_s, 51.0 / kFps, 1e-12);
  EXPECT_NEAR(m.within_100ms_found, (240.0 - 51.0 - 30.0 - 1.0) / (240.0 - 51.0 - 30.0), 1e-12);

  // Held for less than find_hold_s: never found.
  MetricsOptions strict;
  strict.find_hold_s = 5.0;
  const Metrics never = t.metrics(strict);
  EXPECT_TRUE(std::isinf(never.median_find_s));
  EXPECT_DOUBLE_EQ(never.within_100ms_found, 0.0);
}

TEST(Metrics, FindingPoolsAsAMedianOverPerformances) {
  Trace found_at_once(120), found_late(240), never(240);
  for (int k = 0; k < 90; ++k) found_late.estimates[static_cast<std::size_t>(k)].take = 1;
  for (auto& e : never.estimates) e.take = 1;
  MetricsAccumulator two;
  two.add(found_at_once.truth, found_at_once.times, found_at_once.estimates, kFps);
  two.add(found_late.truth, found_late.times, found_late.estimates, kFps);
  const Metrics m2 = two.summary();
  EXPECT_NEAR(m2.median_find_s, 0.5 * (90.0 / kFps), 1e-12);
  EXPECT_NEAR(m2.worst_find_s, 90.0 / kFps, 1e-12);
  EXPECT_DOUBLE_EQ(m2.within_100ms_found, 1.0);
  MetricsAccumulator three;
  three.add(never.truth, never.times, never.estimates, kFps);
  three.merge(two);
  const Metrics m3 = three.summary();
  EXPECT_NEAR(m3.median_find_s, 90.0 / kFps, 1e-12);
  EXPECT_TRUE(std::isinf(m3.worst_find_s));
  EXPECT_DOUBLE_EQ(m3.within_100ms_found, 1.0);  // a performance never found adds no frames
}

}  // namespace
}  // namespace duet
