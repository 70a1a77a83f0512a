#include "duet/follow/noise_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace duet {
namespace {

constexpr int kPosture = 20;
constexpr int kDims = kPosture + 2;  // two velocity dimensions, passed through
constexpr double kFps = 60.0;
constexpr double kDensity = 1000.0;
constexpr double kAllowance = 0.002;

// The true (smooth) value of dimension d at time t: slow sines, as a dance's posture moves.
double truth(int d, double t) { return std::sin(2.0 * t + 0.3 * d); }

struct Errors {
  double input_variance = 0.0;   // of the noisy input against the truth
  double output_variance = 0.0;  // of the filtered output against the truth
  double output_mean = 0.0;      // the output's average error: lag shows as a bias
  bool finite = true;
};

// Filters `frames` frames of the smooth path plus white noise of standard deviation sd (posture
// dimensions), told the noise variance sd^2; every `miss_every`-th frame missing (0: none).
// Errors are taken after the first second.
Errors run(double sd, int frames, int miss_every = 0, double dt_s = 1.0 / kFps) {
  NoiseFilter filter(kDims, kPosture, kDensity, kAllowance, kFps);
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, sd);
  std::vector<float> x(kDims, 0.0f);
  Errors e;
  long long count = 0;
  double t = 0.0;
  for (int f = 0; f < frames; ++f) {
    t += dt_s;
    if (miss_every > 0 && f % miss_every == miss_every - 1) {
      filter.miss(dt_s);
      continue;
    }
    for (int d = 0; d < kPosture; ++d) {
      x[static_cast<std::size_t>(d)] = static_cast<float>(truth(d, t) + normal(rng));
    }
    x[kPosture] = static_cast<float>(f);
    x[kPosture + 1] = -1.0f;
    const std::span<const float> out =
        filter.apply(x, dt_s, static_cast<float>(sd * sd + kAllowance));
    EXPECT_EQ(out[kPosture], x[kPosture]);  // velocities pass
    EXPECT_EQ(out[kPosture + 1], x[kPosture + 1]);
    if (t < 1.0) continue;
    for (int d = 0; d < kPosture; ++d) {
      const auto i = static_cast<std::size_t>(d);
      const double in_error = x[i] - truth(d, t);
      const double out_error = out[i] - truth(d, t);
      e.finite = e.finite && std::isfinite(out_error);
      e.input_variance += in_error * in_error;
      e.output_variance += out_error * out_error;
      e.output_mean += out_error;
      ++count;
    }
  }
  e.input_variance /= static_cast<double>(count);
  e.output_variance /= static_cast<double>(count);
  e.output_mean /= static_cast<double>(count);
  return e;
}

TEST(NoiseFilter, RemovesPartOfTheSensorsNoiseWithoutLaggingBehindTheMotion) {
  // About 4 degrees per axis in standardised features (noise variance 0.009). The default
  // density smooths lightly: about 60% of the variance is left at 60 Hz.
  const Errors e = run(0.095, 600);
  ASSERT_TRUE(e.finite);
  EXPECT_NEAR(e.input_variance, 0.095 * 0.095, 0.001);
  EXPECT_LT(e.output_variance, 0.7 * e.input_variance) << e.output_variance;
  EXPECT_LT(std::abs(e.output_mean), 0.01) << e.output_mean;
}

TEST(NoiseFilter, PredictsOverMissingFramesAndSlowerInput) {
  const Errors missing = run(0.095, 600, 4);
  ASSERT_TRUE(missing.finite);
  EXPECT_LT(missing.output_variance, 0.75 * missing.input_variance);
  const Errors slow = run(0.095, 300, 0, 1.0 / 30.0);
  ASSERT_TRUE(slow.finite);
  EXPECT_LT(slow.output_variance, 0.85 * slow.input_variance);
  EXPECT_LT(std::abs(slow.output_mean), 0.01);
}

TEST(NoiseFilter, PassesACleanSensorsInputUnchanged) {
  NoiseFilter filter(kDims, kPosture, kDensity, kAllowance, kFps);
  std::vector<float> x(kDims, 0.0f);
  for (int f = 0; f < 120; ++f) {
    const double t = f / kFps;
    for (int d = 0; d < kDims; ++d) x[static_cast<std::size_t>(d)] = static_cast<float>(truth(d, t));
    // A clean sensor's estimate, up to the allowance: no smoothing, no lag.
    const std::span<const float> out = filter.apply(x, 1.0 / kFps, 0.0015f);
    for (int d = 0; d < kDims; ++d) {
      ASSERT_NEAR(out[static_cast<std::size_t>(d)], x[static_cast<std::size_t>(d)], 1e-6f);
    }
    EXPECT_NEAR(filter.gain(), 1.0, 1e-9);
  }
}

TEST(NoiseFilter, AnInputFarOutsideThePredictionStartsItOver) {
  // Noisy frames at one place, then the sensor reports another place entirely (a glitch, or
  // back after something else): the new place is taken at once, not blended in over frames.
  NoiseFilter filter(kDims, kPosture, kDensity, kAllowance, kFps);
  std::mt19937 rng(9);
  std::normal_distribution<float> normal(0.0f, 0.095f);
  std::vector<float> x(kDims, 0.0f);
  for (int f = 0; f < 60; ++f) {
    for (int d = 0; d < kPosture; ++d) x[static_cast<std::size_t>(d)] = normal(rng);
    filter.apply(x, 1.0 / kFps, 0.011f);
  }
  EXPECT_LT(filter.gain(), 0.9);  // it was smoothing
  std::fill(x.begin(), x.end(), 3.0f);
  const std::span<const float> out = filter.apply(x, 1.0 / kFps, 0.011f);
  for (int d = 0; d < kPosture; ++d) EXPECT_EQ(out[static_cast<std::size_t>(d)], 3.0f);
}

TEST(NoiseFilter, OffOrGivenAnotherSizeItReturnsTheInputItself) {
  std::vector<float> x(kDims, 0.5f);
  NoiseFilter off(kDims, kPosture, 0.0, kAllowance, kFps);
  EXPECT_EQ(off.apply(x, 1.0 / kFps, 0.01f).data(), x.data());
  NoiseFilter on(kDims, kPosture, kDensity, kAllowance, kFps);
  std::vector<float> other(kDims + 1, 0.5f);
  EXPECT_EQ(on.apply(other, 1.0 / kFps, 0.01f).data(), other.data());
  NoiseFilter unsized;
  EXPECT_EQ(unsized.apply(x, 1.0 / kFps, 0.01f).data(), x.data());
}

TEST(NoiseFilter, BadTimingOrNoiseNeverGivesANonFiniteFrame) {
  NoiseFilter filter(kDims, kPosture, kDensity, kAllowance, kFps);
  std::vector<float> x(kDims, 0.25f);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double dt : {1.0 / kFps, 0.0, -1.0, nan, inf, 1e-9, 5.0, 1.0 / kFps}) {
    for (const float noise : {0.01f, std::nanf(""), -1.0f, std::numeric_limits<float>::infinity()}) {
      filter.miss(dt);
      const std::span<const float> out = filter.apply(x, dt, noise);
      for (const float v : out) ASSERT_TRUE(std::isfinite(v)) << dt << " " << noise;
    }
  }
  filter.reset();
  const std::span<const float> first = filter.apply(x, 1.0 / kFps, 0.01f);
  EXPECT_EQ(first[0], 0.25f);  // the first frame after a reset is taken as it is
}

}  // namespace
}  // namespace duet
