// SteadyDifference: the sensed difference as it is on a clean sensor, averaged and trusted by the
// share of it that is not noise under a noisy one.
#include "duet/partner/steady_difference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace duet {
namespace {

constexpr double kDt = 1.0 / 60.0;

struct Outcome {
  double mean_error = 0.0;   // of the output against the real difference
  Vec3 mean = Vec3::Zero();  // of the output
};

// Feeds differences of `real` plus white noise of `sigma` per axis (jitter: its RMS over the
// axes, as the caller's meter reads it); the outcome over the second half.
Outcome run(const Vec3& real, double sigma, double power_time_constant_s) {
  SteadyDifference steady;
  const SteadyDifferenceParams params{0.1, power_time_constant_s};
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0.0, sigma);
  const int frames = 1200;
  Outcome outcome;
  for (int f = 0; f < frames; ++f) {
    const Vec3 sensed = real + Vec3(noise(random), noise(random), noise(random));
    const Vec3 out = steady.update(sensed, std::sqrt(3.0) * sigma, 0.02, kDt, params);
    if (f < frames / 2) continue;
    outcome.mean_error += (out - real).norm() / (frames / 2);
    outcome.mean += out / (frames / 2);
  }
  return outcome;
}

double mean_error(const Vec3& real, double sigma, double power_time_constant_s) {
  return run(real, sigma, power_time_constant_s).mean_error;
}

TEST(SteadyDifference, PassesACleanDifferenceAsItIs) {
  SteadyDifference steady;
  for (int f = 0; f < 60; ++f) {
    const Vec3 difference(0.01 * f, -0.02, 0.03);
    EXPECT_TRUE(steady.update(difference, 0.0, 0.02, kDt, {}).isApprox(difference, 1e-12));
  }
}

TEST(SteadyDifference, TrustsLessOfANoiseAsLargeAsTheDifference) {
  // 3 cm of noise per axis on a 1 cm difference: trusting the average whole leaves its noise,
  // trusting the share of its power that is real comes closer.
  const Vec3 real(0.01, 0.0, 0.0);
  const double trusted = mean_error(real, 0.03, 0.0);
  const double shrunk = mean_error(real, 0.03, 1.0);
  EXPECT_LT(shrunk, 0.8 * trusted);
  // With no real difference the output falls towards none.
  EXPECT_LT(mean_error(Vec3::Zero(), 0.03, 1.0), 0.6 * mean_error(Vec3::Zero(), 0.03, 0.0));
}

TEST(SteadyDifference, KeepsALargeRealDifferenceUnderNoise) {
  // A 10 cm difference under 3 cm of noise is mostly real: over 90 % of it is kept, and the
  // error is about that of the average trusted whole.
  const Outcome shrunk = run(Vec3(0.1, 0.0, 0.0), 0.03, 1.0);
  EXPECT_GT(shrunk.mean.x(), 0.09);
  EXPECT_LT(shrunk.mean_error, 1.1 * mean_error(Vec3(0.1, 0.0, 0.0), 0.03, 0.0));
}

TEST(SteadyDifference, SkipsANonFiniteDifference) {
  SteadyDifference steady;
  const Vec3 first(0.1, 0.2, 0.3);
  steady.update(first, 0.0, 0.02, kDt, {});
  const Vec3 out = steady.update(Vec3(NAN, 0.0, 0.0), 0.0, 0.02, kDt, {});
  EXPECT_TRUE(out.isApprox(first));
  EXPECT_TRUE(out.allFinite());
  EXPECT_TRUE(steady.update(first, NAN, 0.02, NAN, {}).allFinite());
}

}  // namespace
}  // namespace duet
