#include "duet/follow/explained_residual.h"

#include <gtest/gtest.h>

#include <cmath>

namespace duet {
namespace {

constexpr double kDt = 1.0 / 60.0;
constexpr double kFps = 60.0;

TEST(ExplainedResidual, LearnsOnlyWithinAnUnbrokenRunOfFollowing) {
  ExplainedResidual r;
  // Frames in short runs (broken every 0.5 s by a jump or pause) teach nothing.
  for (int f = 0; f < 600; ++f) r.update(0.002f, f % 30 != 0, 1, kDt, kFps);
  EXPECT_EQ(r.level(), 0.0f);
  // A long run teaches: after the first second, an average from 0 with a 4 s time constant.
  for (int f = 0; f < 60 + 4 * 60; ++f) r.update(0.002f, true, 1, kDt, kFps);
  EXPECT_NEAR(r.level(), 0.002f * (1.0f - std::exp(-1.0f)), 0.0001f);
  for (int f = 0; f < 60 * 60; ++f) r.update(0.002f, true, 1, kDt, kFps);
  EXPECT_NEAR(r.level(), 0.002f, 1e-5f);
}

TEST(ExplainedResidual, LearnsOnlyWhileTheEstimateMovesAtADancersPace) {
  // A wave held one template frame for a second at a time between jumps, unbroken: the estimate
  // that does not move through the template teaches nothing, however long the run.
  ExplainedResidual r;
  for (int f = 0; f < 60 * 60; ++f) r.update(0.002f, true, f % 10 == 0 ? 1 : 0, kDt, kFps);
  EXPECT_EQ(r.level(), 0.0f);
  // Steps back are no pace either; a far unreported move does not make up for a held frame.
  for (int f = 0; f < 60 * 60; ++f) r.update(0.002f, true, f % 2 == 0 ? -1 : 1, kDt, kFps);
  EXPECT_EQ(r.level(), 0.0f);
  for (int f = 0; f < 60 * 60; ++f) r.update(0.002f, true, f % 20 == 0 ? 500 : 0, kDt, kFps);
  EXPECT_EQ(r.level(), 0.0f);
  // A dancer at 0.7x tempo, input at 30 Hz (about 1.4 template frames a frame), teaches.
  for (int f = 0; f < 60 * 30; ++f) r.update(0.002f, true, f % 5 < 2 ? 2 : 1, 2 * kDt, kFps);
  EXPECT_NEAR(r.level(), 0.002f, 1e-4f);
}

TEST(ExplainedResidual, IsCappedAndIgnoresBadInput) {
  ExplainedResidual r;
  for (int f = 0; f < 60 * 60; ++f) r.update(1.0f, true, 1, kDt, kFps);  // far: at most the cap
  EXPECT_NEAR(r.level(), ExplainedResidual::kMaxResidual, 1e-5f);
  const float before = r.level();
  r.update(std::nanf(""), true, 1, kDt, kFps);
  r.update(-1.0f, true, 1, kDt, kFps);  // a missing frame's best distance
  r.update(0.0f, true, 1, std::nan(""), kFps);
  r.update(0.0f, true, 1, kDt, std::nan(""));
  EXPECT_TRUE(std::isfinite(r.level()));
  EXPECT_LE(r.level(), before);
  r.reset();
  EXPECT_EQ(r.level(), 0.0f);
}

}  // namespace
}  // namespace duet
