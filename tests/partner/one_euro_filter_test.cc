// The 1-euro filter: removes jitter from a still signal, follows a moving one with little lag,
// restarts cleanly and never returns NaN.
#include "duet/partner/one_euro_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "duet/math/rotation.h"

namespace duet {
namespace {

constexpr double kDt = 1.0 / 60;

TEST(OneEuroFilter, RemovesMostJitterFromAStillSignal) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);  // 1 cm per axis, every frame
  OneEuroFilter3 filter;
  const OneEuroParams params;
  double raw_step = 0.0, filtered_step = 0.0;
  Vec3 previous_raw = Vec3::Zero(), previous_filtered = Vec3::Zero();
  const int frames = 3000;
  for (int t = 0; t < frames; ++t) {
    const Vec3 raw(noise(rng), noise(rng), noise(rng));
    const Vec3 filtered = filter.filter(raw, kDt, params);
    if (t > 0) {
      raw_step += (raw - previous_raw).norm();
      filtered_step += (filtered - previous_filtered).norm();
    }
    previous_raw = raw;
    previous_filtered = filtered;
  }
  // Frame-to-frame movement (what makes a partner skate) falls by more than 4x.
  EXPECT_LT(filtered_step, raw_step / 4.0);
}

TEST(OneEuroFilter, FollowsAMovingSignalWithLittleLag) {
  OneEuroFilter3 filter;
  const OneEuroParams params;
  Vec3 out = Vec3::Zero();
  for (int t = 0; t <= 120; ++t) out = filter.filter(Vec3(1.0 * t * kDt, 0.0, 0.0), kDt, params);
  // 1 m/s for 2 s: the output trails by under 2.5 cm (a fixed 1 Hz low-pass would trail 16 cm).
  EXPECT_NEAR(out.x(), 2.0, 0.025);
  EXPECT_LT(out.x(), 2.0);
}

TEST(OneEuroFilter, StartsAndRestartsFromTheSampleAndIgnoresNonFiniteInput) {
  OneEuroFilter3 filter;
  const OneEuroParams params;
  EXPECT_FALSE(filter.primed());
  EXPECT_EQ(filter.filter(Vec3(1, 2, 3), kDt, params), Vec3(1, 2, 3));
  const Vec3 nan(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
  EXPECT_EQ(filter.filter(nan, kDt, params), Vec3(1, 2, 3));
  // A broken time step restarts from the sample rather than dividing by zero.
  EXPECT_EQ(filter.filter(Vec3(4, 5, 6), 0.0, params), Vec3(4, 5, 6));
  filter.reset();
  EXPECT_EQ(filter.filter(Vec3(7, 8, 9), kDt, params), Vec3(7, 8, 9));
}

TEST(OneEuroFilter, RebaseMovesTheStateWithTheFrame) {
  // A signal moving along +x at 1 m/s, expressed in a frame that then turns by 90 degrees about
  // +y and shifts by (0, 0, 2): after the rebase the filter continues as if it had always seen the
  // signal in the new frame, with no jump and no catch-up.
  const OneEuroParams params;
  OneEuroFilter3 moved, fresh;
  const Quat turn = yaw_rotation(kPi / 2.0);
  const Vec3 shift(0.0, 0.0, 2.0);
  Vec3 out = Vec3::Zero();
  for (int t = 0; t <= 60; ++t) {
    const Vec3 sample(1.0 * t * kDt, 0.0, 0.0);
    out = moved.filter(sample, kDt, params);
    fresh.filter(turn * sample + shift, kDt, params);
  }
  moved.rebase(turn, shift);
  EXPECT_TRUE(moved.value().isApprox(turn * out + shift, 1e-12));
  EXPECT_TRUE(moved.value().isApprox(fresh.value(), 1e-9));
  for (int t = 61; t <= 90; ++t) {
    const Vec3 sample = turn * Vec3(1.0 * t * kDt, 0.0, 0.0) + shift;
    EXPECT_TRUE(moved.filter(sample, kDt, params).isApprox(fresh.filter(sample, kDt, params), 1e-9))
        << t;
  }
}

TEST(OneEuroFilter, ValidatesItsParameters) {
  OneEuroParams params;
  EXPECT_STREQ(params.validate(), "");
  params.min_cutoff_hz = 0.0;
  EXPECT_NE(std::string(params.validate()).find("min_cutoff_hz"), std::string::npos);
  params = {};
  params.beta = -1.0;
  EXPECT_NE(std::string(params.validate()).find("beta"), std::string::npos);
  params = {};
  params.derivative_cutoff_hz = std::numeric_limits<double>::infinity();
  EXPECT_NE(std::string(params.validate()).find("derivative_cutoff_hz"), std::string::npos);
}

}  // namespace
}  // namespace duet
