// Issue 11 on real takes: under a noisy sensor the follower estimates the noise, keeps following
// without calling the dance lost, and its confidence says how often it is right.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

#include "duet/eval/metrics.h"
#include "duet/eval/performance.h"
#include "duet/eval/runner.h"
#include "duet/follow/hmm_follower.h"
#include "duet/live/follow_session.h"
#include "salsa_library.h"

namespace duet {
namespace {

struct NoisyRun {
  Metrics metrics;
  double mean_noise = 0.0;
};

// Take 01 performed by `recipe` (seed `seed`) and followed by the HMM through the salsa library.
struct FollowedTake {
  Performance performance;
  std::vector<FrameEstimate> estimates;  // empty when either step failed (a test failure)
};

FollowedTake follow_take_01(const PerformanceRecipe& recipe, std::uint64_t seed) {
  const DuetLibrary& library = test::salsa_library();
  const DuetTake& take = library.takes()[0];
  const SourceTake source{0, &take.template_motion.clip, take.template_motion.roles};
  FollowedTake followed;
  Result<Performance> performance = make_performance({&source, 1}, recipe, seed);
  if (!performance) {
    ADD_FAILURE() << performance.error().message;
    return followed;
  }
  followed.performance = std::move(performance).value();
  Result<std::unique_ptr<Tracker>> tracker =
      make_eval_tracker(TrackerKind::kHmm, library.model(), EvalOptions{});
  EXPECT_TRUE(tracker);
  if (!tracker) return followed;
  Result<std::vector<FrameEstimate>> estimates =
      follow_performance(library, followed.performance, std::move(tracker).value());
  EXPECT_TRUE(estimates) << estimates.error().message;
  if (estimates) followed.estimates = std::move(estimates).value();
  return followed;
}

// Take 01 played whole at rate_hz with rotation noise (RMS per joint) and 1 cm root noise.
NoisyRun follow_noisy(double rotation_deg, double rate_hz) {
  PerformanceRecipe recipe;
  recipe.play.rate_hz = rate_hz;
  recipe.noise = {rotation_deg, 0.01, 0};
  const FollowedTake followed = follow_take_01(recipe, 11);
  NoisyRun run;
  if (followed.estimates.empty()) return run;
  run.metrics = compute_metrics(followed.performance, followed.estimates);
  for (const FrameEstimate& e : followed.estimates) run.mean_noise += e.sensor_noise_per_dim;
  run.mean_noise /= static_cast<double>(followed.estimates.size());
  return run;
}

TEST(NoisySensorFollow, FourDegreesPerAxisAtThirtyHertzIsFollowedNotLost) {
  // 4 degrees per axis = 6.93 degrees RMS per joint. Before the noise-scaled pause level and lost
  // distance, 30% of the frames followed within 100 ms were flagged lost and the confidence's
  // calibration error was 24%.
  const NoisyRun noisy = follow_noisy(6.93, 30.0);
  const NoisyRun clean = follow_noisy(0.0, 30.0);
  std::printf(
      "4 deg/axis at 30 Hz: %.1f%% within 100 ms, lost on tracked %.2f%%, ECE %.2f%%, "
      "%.1f false jumps/min, noise %.5f (clean %.6f)\n",
      100.0 * noisy.metrics.within_100ms, 100.0 * noisy.metrics.lost_on_tracked_fraction,
      100.0 * noisy.metrics.confidence_ece, noisy.metrics.false_jumps_per_minute, noisy.mean_noise,
      clean.mean_noise);
  EXPECT_GT(noisy.mean_noise, 20.0 * clean.mean_noise);
  EXPECT_LE(noisy.metrics.lost_on_tracked_fraction, 0.02);
  EXPECT_LE(noisy.metrics.confidence_ece, 0.05);
  // 98.2% (84.9% before the noise-scaled pause level, 89.6% before the emission widened with the
  // noise).
  EXPECT_GE(noisy.metrics.within_100ms, 0.95);
  // 6.4 a minute (the 30hz-noisy case at this noise reported 136 before the emission widened).
  EXPECT_LE(noisy.metrics.false_jumps_per_minute, 10.0);
  EXPECT_EQ(clean.metrics.lost_on_tracked_fraction, 0.0);
  EXPECT_LE(clean.metrics.confidence_ece, 0.02);
}

// The HMM follower through FollowSession with the posture offset's params `bias`, scored.
// Where between frames the posterior puts the dancer (FollowResult::frame_offset, the partner's
// playhead aims there) is nearer the truth than the whole frame chosen: on take 01 at 0.85 of its
// tempo with 2 degrees per axis, mean error 9.8 -> 8.5 ms (session 55).
TEST(NoisySensorFollow, ThePlaceBetweenFramesIsNearerTheTruthThanTheFrame) {
  PerformanceRecipe recipe;
  recipe.play.tempo.factor = 0.85;
  recipe.noise = {3.46, 0.01, 0};  // 2 degrees per axis
  const FollowedTake followed = follow_take_01(recipe, 5);
  ASSERT_FALSE(followed.estimates.empty());
  double whole = 0.0, between = 0.0;
  int counted = 0, offsets = 0;
  for (std::size_t i = 0; i < followed.estimates.size(); ++i) {
    const FrameEstimate& e = followed.estimates[i];
    const TruthFrame& truth = followed.performance.truth[i];
    const double error = e.frame_in_take - truth.template_frame;
    if (e.take != truth.take || e.lost || std::abs(error) > 6.0) continue;
    ASSERT_TRUE(std::isfinite(e.frame_offset));
    EXPECT_LE(std::abs(e.frame_offset), 6.0f);  // within the confidence window
    whole += std::abs(error);
    between += std::abs(error + e.frame_offset);
    ++counted;
    if (e.frame_offset != 0.0f) ++offsets;
  }
  std::printf("mean error %.2f ms at the frame, %.2f ms between frames (%d frames)\n",
              1000.0 * whole / counted / 60.0, 1000.0 * between / counted / 60.0, counted);
  ASSERT_GT(counted, static_cast<int>(0.9 * static_cast<double>(followed.estimates.size())));
  EXPECT_GT(offsets, counted / 2);
  EXPECT_LT(between, 0.95 * whole);
}

Metrics follow_with(const DuetLibrary& library, const Performance& performance,
                    const PostureBiasParams& bias) {
  Result<std::unique_ptr<Tracker>> tracker =
      make_eval_tracker(TrackerKind::kHmm, library.model(), EvalOptions{});
  EXPECT_TRUE(tracker);
  Result<std::vector<FrameEstimate>> estimates =
      follow_performance(library, performance, std::move(tracker).value(), bias);
  EXPECT_TRUE(estimates) << estimates.error().message;
  return compute_metrics(performance, estimates.value());
}

// Means over `suits` inertial suits (seeds 1..suits: 5 degrees of calibration and 5 of drift per
// joint, 3 degrees of white noise, 1 cm at the root) of one take followed with today's posture
// offset (now) and with `before`'s (then). Prints each suit's figures.
struct SuitComparison {
  double now_within = 0.0, then_within = 0.0, now_false = 0.0, then_false = 0.0;
};

SuitComparison compare_through_suits(int take_index, int suits, const PostureBiasParams& before,
                                     const char* before_name) {
  const DuetLibrary& library = test::salsa_library();
  const DuetTake& take = library.takes()[static_cast<std::size_t>(take_index)];
  const SourceTake source{take_index, &take.template_motion.clip, take.template_motion.roles};
  SuitComparison mean;
  for (int seed = 1; seed <= suits; ++seed) {
    PerformanceRecipe recipe;
    recipe.noise = {3.0, 0.01, 0};
    recipe.noise.bias_deg = 5.0;
    recipe.noise.drift_deg = 5.0;
    Result<Performance> performance =
        make_performance({&source, 1}, recipe, static_cast<std::uint64_t>(seed));
    EXPECT_TRUE(performance) << performance.error().message;
    if (!performance) return mean;
    auto follow = [&](const PostureBiasParams& bias) {
      return follow_with(library, performance.value(), bias);
    };
    const Metrics now = follow({});
    const Metrics then = follow(before);
    std::printf("suit %d, take %s: %.1f%% within 100 ms, %.1f false jumps/min (%s: %.1f%%, %.1f)\n",
                seed, take.name.c_str(), 100.0 * now.within_100ms, now.false_jumps_per_minute,
                before_name, 100.0 * then.within_100ms, then.false_jumps_per_minute);
    mean.now_within += now.within_100ms / suits;
    mean.then_within += then.within_100ms / suits;
    mean.now_false += now.false_jumps_per_minute / suits;
    mean.then_false += then.false_jumps_per_minute / suits;
  }
  return mean;
}

TEST(NoisySensorFollow, AnInertialSuitsCalibrationAndDriftAreLearntAway) {
  // Take 07 through an inertial suit: every joint off by 5 degrees of calibration and 5 degrees
  // of drift (10 s), with the default 3 degrees of white noise; four suits (seeds). The posture
  // offset must follow the drift: session 9's offset (a 4 s average, taught only by frames within
  // 0.005 of their match) let the drift carry the input out of its reach. Measured: 97.5 / 97.7 /
  // 99.6 / 100 % within 100 ms (91.8 % for suit 1 with the learning limit of 0.01 before session
  // 23; session 9's: 91.0 / 94.3 / 99.7 / 100 %).
  PostureBiasParams before;
  before.time_constant_s = 4.0;
  before.max_learn_distance_per_dim = 0.005f;
  const SuitComparison suits = compare_through_suits(6, 4, before, "session 9's offset");
  EXPECT_GT(suits.now_within, suits.then_within);
  EXPECT_LT(suits.now_false, suits.then_false);
}

TEST(NoisySensorFollow, ASuitFarFromItsMatchStillTeachesTheOffset) {
  // Take 60_10 through an inertial suit (5 + 5 degrees, 3 degrees of white noise), ten suits:
  // its standing start can teach the offset against another standing frame, and its first steps
  // then match no frame closer than 0.010-0.014 per dimension. Taught only by frames within
  // 0.01 (the limit until session 23), the offset could not catch up and the follower hopped
  // between places. Measured: 12.0 -> 5.7 false jumps a minute, 80.2 -> 79.9 % within 100 ms
  // (7 suits the same, one 65 -> 77 %, one 43 -> 28 %: a first match taught against the wrong
  // frame locks in either way; over 84 suit-drift runs of `duet eval`, every take and six seeds,
  // 93.9 -> 94.8 % and 2.8 -> 2.2 false jumps a minute). Since session 28 the first placement
  // settles only once the estimate moves forward through its take (jump_settle_advance_s), and the
  // standing start's hops are no longer jumps either way: 2.7 false jumps a minute with today's
  // limit (5.7 before), 0.4 with 0.01; suit 1, its first match locked in on the wrong frame,
  // keeps 21 a minute with today's limit.
  PostureBiasParams before;
  before.max_learn_distance_per_dim = 0.01f;
  const SuitComparison suits = compare_through_suits(8, 10, before, "taught within 0.01");
  EXPECT_GT(suits.now_within, suits.then_within - 0.01);
  EXPECT_LT(suits.now_false, 4.0);
}

TEST(NoisySensorFollow, ASuitCalibratedFarOffHasItsOffsetFoundWhileLost) {
  // Take 60_14 through a suit 8 degrees off per joint (no drift; 3 degrees of white noise): every
  // frame is 0.010-0.022 per dimension from its match, beyond what may teach the posture offset,
  // the pause state holds the input and the follower was lost for its first 15 s. The offset
  // search (offset_search.h) finds the offset along the dance. Of 30 suits (seeds) one is lost
  // so with today's offset average (1 s on this steady a sensor): suit 4, 26.2 -> 66.2 % within
  // 100 ms (81.6 -> 32.6 % lost); the other 29 the same to the digit, suit 1 among them (with the
  // 2 s average before session 31, suit 24 too: 38.3 -> 71.0 %). Printed per suit.
  const DuetLibrary& library = test::salsa_library();
  const DuetTake& take = library.takes()[12];
  const SourceTake source{12, &take.template_motion.clip, take.template_motion.roles};
  PostureBiasParams without;
  without.search.enabled = false;
  double lost_with = 0.0, lost_without = 0.0, within_with = 0.0, within_without = 0.0;
  for (const std::uint64_t seed : {1, 4}) {
    PerformanceRecipe recipe;
    recipe.noise = {3.0, 0.01, 0};
    recipe.noise.bias_deg = 8.0;
    Result<Performance> performance = make_performance({&source, 1}, recipe, seed);
    ASSERT_TRUE(performance) << performance.error().message;
    auto follow = [&](const PostureBiasParams& bias) {
      return follow_with(library, performance.value(), bias);
    };
    const Metrics with = follow({});
    const Metrics off = follow(without);
    std::printf(
        "suit %d off by 8 deg, take %s: %.1f%% within 100 ms, %.1f%% lost (without the "
        "search: %.1f%%, %.1f%%)\n",
        static_cast<int>(seed), take.name.c_str(), 100.0 * with.within_100ms,
        100.0 * with.lost_fraction, 100.0 * off.within_100ms, 100.0 * off.lost_fraction);
    EXPECT_GE(with.within_100ms, off.within_100ms) << "suit " << seed;
    lost_with += with.lost_fraction / 2.0;
    lost_without += off.lost_fraction / 2.0;
    within_with += with.within_100ms / 2.0;
    within_without += off.within_100ms / 2.0;
  }
  EXPECT_LT(lost_with, 0.6 * lost_without);
  EXPECT_GT(within_with, within_without + 0.15);
}

TEST(NoisySensorFollow, ARepeatedFrameReachesTheFollowerAsMissing) {
  // A sensor that sends its last sample again: 5 % of take 01's frames at 30 Hz under 4 degrees
  // per axis. Each repeat reaches the tracker as a missing frame: the band moves on, and the
  // stale pose neither pulls the estimate back nor enters the velocities. 98.8 % within 100 ms
  // (94.4 % with the repeats taken as evidence).
  const DuetLibrary& library = test::salsa_library();
  const DuetTake& take = library.takes()[0];
  const SourceTake source{0, &take.template_motion.clip, take.template_motion.roles};
  PerformanceRecipe recipe;
  recipe.play.rate_hz = 30.0;
  recipe.noise = {6.93, 0.01, 0};
  recipe.loss.repeat_fraction = 0.05;
  Result<Performance> made = make_performance({&source, 1}, recipe, 12);
  ASSERT_TRUE(made) << made.error().message;
  const Performance& performance = made.value();
  Result<HmmFollower> follower = HmmFollower::create(library.model(), FollowParams{});
  ASSERT_TRUE(follower);
  Result<FollowSession> session =
      FollowSession::create(library, performance.motion.skeleton_ptr(), performance.roles,
                            std::make_unique<HmmFollower>(std::move(follower).value()));
  ASSERT_TRUE(session) << session.error().message;
  const Clip& motion = performance.motion;
  int repeats = 0, missing_elsewhere = 0;
  std::vector<FrameEstimate> estimates;
  for (int f = 0; f < motion.frame_count(); ++f) {
    const auto same_pose = [&] {
      if (f == 0) return false;
      const auto t0 = motion.translations_ls(f - 1), t1 = motion.translations_ls(f);
      const auto r0 = motion.rotations_ls(f - 1), r1 = motion.rotations_ls(f);
      for (std::size_t j = 0; j < t1.size(); ++j) {
        if (t0[j] != t1[j] || r0[j].coeffs() != r1[j].coeffs()) return false;
      }
      return true;
    };
    const bool repeat = same_pose();
    const FollowResult r = session.value().step(motion.translations_ls(f), motion.rotations_ls(f),
                                                performance.times_s[static_cast<std::size_t>(f)]);
    if (repeat) {
      ++repeats;
      EXPECT_TRUE(r.missing) << f;
    } else if (r.missing) {
      ++missing_elsewhere;
    }
    estimates.push_back(frame_estimate(r));
  }
  EXPECT_GT(repeats, 20);
  EXPECT_EQ(missing_elsewhere, 0);
  const Metrics m = compute_metrics(performance, estimates);
  std::printf(
      "take 01, 30 Hz, 4 deg/axis, %d repeated frames: %.1f%% within 100 ms, %.1f false "
      "jumps/min\n",
      repeats, 100.0 * m.within_100ms, m.false_jumps_per_minute);
  EXPECT_GE(m.within_100ms, 0.95);
}

TEST(NoisySensorFollow, AStalledSensorIsFollowedThroughAtTheDancersTempo) {
  // Take 01 under the noise, the sensor holding its last pose for 0.3-2 s every 8 s while the
  // dancer dances on (a stalled stream, a headset that lost tracking). The held copies are no
  // evidence: the tempo carries the estimate through, and the dancer is found where they went.
  // Taken as evidence (before) the held pose was followed as a standing still dancer and sent
  // to a take's standing start: the `stalls` case 87.2 % within 100 ms, 6.2 false jumps a minute.
  const DuetLibrary& library = test::salsa_library();
  const DuetTake& take = library.takes()[0];
  const SourceTake source{0, &take.template_motion.clip, take.template_motion.roles};
  PerformanceRecipe recipe;
  recipe.noise = {3.0, 0.005, 0};
  recipe.loss.freeze_every_s = 8.0;
  Result<Performance> made = make_performance({&source, 1}, recipe, 3);
  ASSERT_TRUE(made) << made.error().message;
  const Performance& performance = made.value();
  Result<FollowSession> session = FollowSession::create(
      library, performance.motion.skeleton_ptr(), performance.roles,
      std::make_unique<HmmFollower>(HmmFollower::create(library.model(), FollowParams{}).value()));
  ASSERT_TRUE(session) << session.error().message;
  const Clip& motion = performance.motion;
  int held = 0;
  std::vector<FrameEstimate> estimates;
  for (int f = 0; f < motion.frame_count(); ++f) {
    const FollowResult r = session.value().step(motion.translations_ls(f), motion.rotations_ls(f),
                                                performance.times_s[static_cast<std::size_t>(f)]);
    held += r.missing ? 1 : 0;
    estimates.push_back(frame_estimate(r));
  }
  const Metrics m = compute_metrics(performance, estimates);
  std::printf("take 01, stalls: %d held frames, %.1f%% within 100 ms, %.1f false jumps/min\n", held,
              100.0 * m.within_100ms, m.false_jumps_per_minute);
  EXPECT_GT(held, 120);  // seconds of stalls
  EXPECT_GE(m.within_100ms, 0.98);
  EXPECT_EQ(m.false_jumps_per_minute, 0.0);
  EXPECT_LE(m.lost_fraction, 0.01);
}

}  // namespace
}  // namespace duet
