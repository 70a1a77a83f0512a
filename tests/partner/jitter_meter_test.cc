// JitterMeter: the jitter of a signal around its own smooth course, not the course's motion.
#include "duet/partner/jitter_meter.h"

#include <gtest/gtest.h>

#include <cmath>

namespace duet {
namespace {

constexpr double kDt = 1.0 / 60.0;

TEST(JitterMeter, ReadsWhiteJitterAndNotASteadyMotionOrATurn) {
  // +-0.05 rad of pseudo-random white jitter on a yaw turning at 2 rad/s with a changing rate.
  JitterMeter noisy, smooth;
  unsigned state = 7u;
  for (int f = 0; f < 600; ++f) {
    const double t = f * kDt;
    const double course = 2.0 * t + 0.5 * std::sin(3.0 * t);
    state = state * 1664525u + 1013904223u;
    const double jitter = (state >> 31) != 0u ? 0.05 : -0.05;
    noisy.add(course + jitter, kDt, 1.0, 0.5);
    smooth.add(course, kDt, 1.0, 0.5);
  }
  EXPECT_NEAR(noisy.rms(), 0.05, 0.012);
  EXPECT_LT(smooth.rms(), 0.002);
}

TEST(JitterMeter, AMoveIsNoJitterAndARestartKeepsTheReading) {
  JitterMeter meter;
  for (int f = 0; f < 120; ++f) meter.add(f * 0.01, kDt, 1.0, 0.5);
  meter.add(5.0, kDt, 1.0, 0.5);  // a step of 4 in one frame: a move
  EXPECT_LT(meter.rms(), 1e-6);
  for (int f = 0; f < 300; ++f) meter.add((f % 2 != 0) ? 0.1 : -0.1, kDt, 1.0, 0.5);
  const double before = meter.rms();
  EXPECT_GT(before, 0.05);
  meter.restart();  // new samples start over, the reading stays
  meter.add(100.0, kDt, 1.0, 0.5);
  meter.add(100.0, kDt, 1.0, 0.5);
  EXPECT_DOUBLE_EQ(meter.rms(), before);
  meter.add(std::nan(""), kDt, 1.0, 0.5);  // ignored
  EXPECT_DOUBLE_EQ(meter.rms(), before);
  meter.reset();
  EXPECT_EQ(meter.rms(), 0.0);
}

}  // namespace
}  // namespace duet
