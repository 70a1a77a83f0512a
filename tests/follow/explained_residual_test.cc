#include "duet/follow/explained_residual.h"

#include <gtest/gtest.h>

#include <cmath>

namespace duet {
namespace {

constexpr double kDt = 1.0 / 60.0;

TEST(ExplainedResidual, LearnsOnlyWithinAnUnbrokenRunOfFollowing) {
  ExplainedResidual r;
  // Frames in short runs (broken every 0.5 s by a jump or pause) teach nothing.
  for (int f = 0; f < 600; ++f) r.update(0.002f, f % 30 != 0, kDt);
  EXPECT_EQ(r.level(), 0.0f);
  // A long run teaches: after the first second, an average from 0 with a 4 s time constant.
  for (int f = 0; f < 60 + 4 * 60; ++f) r.update(0.002f, true, kDt);
  EXPECT_NEAR(r.level(), 0.002f * (1.0f - std::exp(-1.0f)), 0.0001f);
  for (int f = 0; f < 60 * 60; ++f) r.update(0.002f, true, kDt);
  EXPECT_NEAR(r.level(), 0.002f, 1e-5f);
}

TEST(ExplainedResidual, IsCappedAndIgnoresBadInput) {
  ExplainedResidual r;
  for (int f = 0; f < 60 * 60; ++f) r.update(1.0f, true, kDt);  // far: teaches at most the cap
  EXPECT_NEAR(r.level(), ExplainedResidual::kMaxResidual, 1e-5f);
  const float before = r.level();
  r.update(std::nanf(""), true, kDt);
  r.update(-1.0f, true, kDt);  // a missing frame's best distance
  r.update(0.0f, true, std::nan(""));
  EXPECT_TRUE(std::isfinite(r.level()));
  EXPECT_LE(r.level(), before);
  r.reset();
  EXPECT_EQ(r.level(), 0.0f);
}

}  // namespace
}  // namespace duet
