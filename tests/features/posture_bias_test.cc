#include "duet/features/posture_bias.h"

#include <gtest/gtest.h>

#include <cmath>
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
