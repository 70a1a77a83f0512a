#include "duet/features/posture_bias.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace duet {
namespace {

TEST(PostureBias, LearnsAConstantOffsetAndRemovesIt) {
  PostureBias bias(1, 2, {});
  const std::vector<float> matched = {0.0f, 0.5f, -0.5f, 7.0f};
  // The input is the matched row plus a rig offset on the two posture dimensions (and a
  // different velocity, dimension 3, which is not adapted).
  std::vector<float> x(4);
  for (int f = 0; f < 600; ++f) {  // 10 s at 60 Hz
    x = {0.0f, 0.5f + 0.8f, -0.5f - 0.3f, 9.0f};
    bias.correct(x);
    bias.learn(x, matched, 1.0 / 60.0, 1.0f);
  }
  EXPECT_NEAR(bias.offset()[0], 0.8f, 0.01f);
  EXPECT_NEAR(bias.offset()[1], -0.3f, 0.01f);
  x = {0.0f, 1.3f, -0.8f, 9.0f};
  bias.correct(x);
  EXPECT_NEAR(x[1], 0.5f, 0.01f);
  EXPECT_NEAR(x[2], -0.5f, 0.01f);
  EXPECT_EQ(x[3], 9.0f);  // outside the adapted block
  bias.reset();
  EXPECT_EQ(bias.offset()[0], 0.0f);
}

TEST(PostureBias, AnOffsetHeldThroughFourSecondsLostIsLetGo) {
  const std::vector<float> matched = {0.0f, 0.0f};
  const auto learnt = [&](float offset) {
    PostureBias bias(0, 2, {});
    for (int f = 0; f < 300; ++f) {
      std::vector<float> x = {offset, -offset};
      bias.correct(x);
      bias.learn(x, matched, 1.0 / 60.0, 1.0f);
    }
    return bias;
  };
  PostureBias bias = learnt(0.3f);
  ASSERT_NEAR(bias.offset()[0], 0.3f, 0.01f);
  for (int f = 0; f < 230; ++f) bias.note_lost(true, 1.0 / 60.0);  // 3.8 s
  // 0.25 s followed in a row (release_found_s): the count starts again.
  for (int f = 0; f < 15; ++f) bias.note_lost(false, 1.0 / 60.0);
  for (int f = 0; f < 230; ++f) bias.note_lost(true, 1.0 / 60.0);
  EXPECT_NEAR(bias.offset()[0], 0.3f, 0.01f);
  // A flicker of 14 frames followed does not break the run; it adds nothing to it either.
  for (int f = 0; f < 14; ++f) bias.note_lost(false, 1.0 / 60.0);
  EXPECT_NEAR(bias.offset()[0], 0.3f, 0.01f);
  for (int f = 0; f < 20; ++f) bias.note_lost(true, 1.0 / 60.0);  // past 4 s in a row
  EXPECT_EQ(bias.offset()[0], 0.0f);
  EXPECT_EQ(bias.offset()[1], 0.0f);

  // An offset the size the library's own rig shows is kept however long the input is lost.
  PostureBias small = learnt(0.005f);
  for (int f = 0; f < 600; ++f) small.note_lost(true, 1.0 / 60.0);
  EXPECT_GT(small.offset()[0], 0.004f);
}

TEST(PostureBias, UnsureFramesCountLessAndBadInputIsIgnored) {
  PostureBias sure(0, 1, {}), unsure(0, 1, {});
  const std::vector<float> matched = {0.0f};
  for (int f = 0; f < 30; ++f) {
    std::vector<float> x = {1.0f};
    sure.correct(x);
    sure.learn(x, matched, 1.0 / 60.0, 1.0f);
    std::vector<float> y = {1.0f};
    unsure.correct(y);
    unsure.learn(y, matched, 1.0 / 60.0, 0.0f);
  }
  EXPECT_GT(sure.offset()[0], unsure.offset()[0]);
  EXPECT_GT(unsure.offset()[0], 0.0f);  // unsure frames still teach something
  const float before = sure.offset()[0];
  const std::vector<float> nan = {std::nanf("")};
  sure.learn(nan, matched, 1.0 / 60.0, 1.0f);
  sure.learn(matched, matched, -1.0, 1.0f);
  EXPECT_EQ(sure.offset()[0], before);
}

TEST(PostureBias, ANoiseSizedAverageIsNotAppliedButARigsOffsetUnderTheSameNoiseIs) {
  // Issue 11: under a noisy sensor the running mean wanders by noise; subtracting that made the
  // follower worse. The applied offset is shrunk by the mean's own uncertainty.
  const float noise_sd = 0.3f;
  PostureBias noise_only(0, 1, {}), rig(0, 1, {}), unshrunk(0, 1, [] {
    PostureBiasParams params;
    params.shrink_k = 0.0;
    return params;
  }());
  const std::vector<float> matched = {0.0f};
  std::uint32_t state = 12345u;
  auto gaussian = [&state] {  // Box-Muller on a small LCG: the test's own noise, reproducible
    auto uniform = [&state] {
      state = state * 1664525u + 1013904223u;
      return (static_cast<float>(state >> 8) + 0.5f) / 16777216.0f;
    };
    const float u = uniform(), v = uniform();
    return std::sqrt(-2.0f * std::log(u)) * std::cos(6.2831853f * v);
  };
  float largest_noise_offset = 0.0f, largest_unshrunk = 0.0f;
  for (int f = 0; f < 1800; ++f) {  // 60 s at 30 Hz
    const float n = noise_sd * gaussian();
    std::vector<float> a = {n}, b = {0.25f + n}, c = {n};
    noise_only.correct(a);
    noise_only.learn(a, matched, 1.0 / 30.0, 1.0f, noise_sd * noise_sd);
    rig.correct(b);
    rig.learn(b, matched, 1.0 / 30.0, 1.0f, noise_sd * noise_sd);
    unshrunk.correct(c);
    unshrunk.learn(c, matched, 1.0 / 30.0, 1.0f, noise_sd * noise_sd);
    if (f >= 300) {
      largest_noise_offset = std::max(largest_noise_offset, std::abs(noise_only.offset()[0]));
      largest_unshrunk = std::max(largest_unshrunk, std::abs(unshrunk.offset()[0]));
    }
  }
  EXPECT_LT(largest_noise_offset, 0.25f * largest_unshrunk);  // the mean wandered, little applied
  EXPECT_GT(largest_unshrunk, 0.02f);
  // The rig's offset: applied, most of it (the 2 s average's uncertainty under this much noise
  // shrinks it by a fifth to a quarter; a 4 s one by a tenth).
  EXPECT_GT(rig.offset()[0], 0.7f * 0.25f);
  EXPECT_LT(rig.offset()[0], 0.25f + 0.05f);
  EXPECT_NEAR(rig.mean()[0], 0.25f, 0.05f);
}

TEST(PostureBias, ARunawayOffsetIsBounded) {
  PostureBiasParams params;
  params.max_offset = 1.5f;
  PostureBias bias(0, 1, params);
  const std::vector<float> matched = {0.0f};
  for (int f = 0; f < 2000; ++f) {
    std::vector<float> x = {100.0f};
    bias.learn(x, matched, 1.0 / 60.0, 1.0f);
  }
  EXPECT_EQ(bias.offset()[0], 1.5f);
}

TEST(PostureBias, FollowsADriftingOffset) {
  // An inertial suit's drift: the offset moves by 0.1 standardised units a second for 12 s. The
  // average (1 s on a steady sensor) lags it by about 0.1 x 1 s; session 10's 2 s average lagged
  // twice as far, the 4 s before it four times.
  auto lag_after_ramp = [](double time_constant_s) {
    PostureBiasParams params;
    params.time_constant_s = time_constant_s;
    PostureBias bias(0, 1, params);
    const std::vector<float> matched = {0.0f};
    float truth = 0.0f;
    for (int f = 0; f < 960; ++f) {  // 4 s settled at 0, then a 12 s ramp to 1.2
      if (f >= 240) truth = 1.2f * static_cast<float>(f - 240) / 720.0f;
      std::vector<float> x = {truth};
      bias.correct(x);
      bias.learn(x, matched, 1.0 / 60.0, 1.0f);
    }
    return truth - bias.offset()[0];
  };
  const float lag = lag_after_ramp(PostureBiasParams{}.time_constant_s);
  EXPECT_GT(lag, 0.07f);
  EXPECT_LT(lag, 0.12f);
  EXPECT_GT(lag_after_ramp(2.0), 1.7f * lag);
  EXPECT_GT(lag_after_ramp(4.0), 3.4f * lag);
}

TEST(PostureBias, TheAverageLengthensAsTheSensorsNoiseRises) {
  // A steady sensor's offset is a suit's calibration and drift, to be followed; a noisy sensor's
  // average must keep its white noise out: as the square root of the noise, between the two.
  const PostureBiasParams params;
  const float level = params.noisy_time_constant_level;
  EXPECT_DOUBLE_EQ(params.time_constant(0.0f), params.time_constant_s);
  EXPECT_DOUBLE_EQ(params.time_constant(level), params.noisy_time_constant_s);
  EXPECT_DOUBLE_EQ(params.time_constant(10.0f * level), params.noisy_time_constant_s);
  EXPECT_NEAR(params.time_constant(0.5625f * level), 0.75 * params.noisy_time_constant_s, 1e-6);
  EXPECT_DOUBLE_EQ(params.time_constant(0.01f * level), params.time_constant_s);
  EXPECT_LT(params.time_constant_s, params.noisy_time_constant_s);
  EXPECT_DOUBLE_EQ(params.time_constant(std::numeric_limits<float>::quiet_NaN()),
                   params.time_constant_s);
  EXPECT_DOUBLE_EQ(params.time_constant(-1.0f), params.time_constant_s);

  // Under that noise the offset follows a step more slowly.
  auto learnt_after_one_second = [](float sensor_noise) {
    PostureBias bias(0, 1, {});
    const std::vector<float> matched = {0.0f};
    for (int f = 0; f < 600; ++f) {  // 10 s at 0.5, then 1 s at 1.5
      std::vector<float> x = {f < 540 ? 0.5f : 1.5f};
      bias.correct(x);
      bias.learn(x, matched, 1.0 / 60.0, 1.0f, sensor_noise);
    }
    return bias.mean()[0];
  };
  EXPECT_NEAR(learnt_after_one_second(0.0f), 1.5f - std::exp(-1.0f), 0.02f);
  EXPECT_NEAR(learnt_after_one_second(level), 1.5f - std::exp(-0.5f), 0.02f);
}

TEST(PostureBias, TheLearningDistanceNarrowsAsTheSensorsNoiseRises) {
  PostureBiasParams params;
  params.learn_noise_factor = 0.0f;  // the narrowing alone
  EXPECT_FLOAT_EQ(params.learn_distance_limit(0.0f), params.max_learn_distance_per_dim);
  EXPECT_FLOAT_EQ(params.learn_distance_limit(params.noisy_learn_level),
                  params.max_learn_distance_noisy_per_dim);
  EXPECT_FLOAT_EQ(params.learn_distance_limit(10.0f * params.noisy_learn_level),
                  params.max_learn_distance_noisy_per_dim);
  const float half = params.learn_distance_limit(0.5f * params.noisy_learn_level);
  EXPECT_LT(half, params.max_learn_distance_per_dim);
  EXPECT_GT(half, params.max_learn_distance_noisy_per_dim);
  // No estimate of the noise (NaN or negative) is a steady sensor's limit, not NaN.
  EXPECT_FLOAT_EQ(params.learn_distance_limit(std::nanf("")), params.max_learn_distance_per_dim);
  EXPECT_FLOAT_EQ(params.learn_distance_limit(-1.0f), params.max_learn_distance_per_dim);
}

TEST(PostureBias, ANoisySensorsRightMatchesStillTeach) {
  const PostureBiasParams params;
  ASSERT_GT(params.learn_noise_factor, 1.0f);
  // At the noise where the narrowing ends, a match as far as the noise itself may teach.
  const float noisy = params.noisy_learn_level;
  EXPECT_FLOAT_EQ(params.learn_distance_limit(noisy), params.learn_noise_factor * noisy);
  EXPECT_GT(params.learn_distance_limit(noisy), params.max_learn_distance_noisy_per_dim);
  // Up to twice that noise the limit is never below the floor nor above a steady sensor's.
  for (float noise = 0.0f; noise <= 2.0f * noisy; noise += 0.0005f) {
    const float limit = params.learn_distance_limit(noise);
    EXPECT_GE(limit, params.learn_noise_factor * noise - 1e-7f) << noise;
    EXPECT_LE(limit, params.max_learn_distance_per_dim) << noise;
  }
  // A noise estimate thrown far up never opens the limit past a steady sensor's.
  EXPECT_FLOAT_EQ(params.learn_distance_limit(1.0f), params.max_learn_distance_per_dim);
  EXPECT_FLOAT_EQ(params.learn_distance_limit(std::numeric_limits<float>::infinity()),
                  params.max_learn_distance_per_dim);
}

TEST(PostureBias, DisabledChangesNothing) {
  PostureBiasParams params;
  params.enabled = false;
  PostureBias bias(0, 1, params);
  std::vector<float> x = {2.0f};
  const std::vector<float> matched = {0.0f};
  bias.learn(x, matched, 0.1, 1.0f);
  bias.correct(x);
  EXPECT_EQ(x[0], 2.0f);
}

}  // namespace
}  // namespace duet
