#include "duet/eval/calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "duet/eval/metrics.h"

namespace duet {
namespace {

TEST(Calibration, AConfidenceThatMatchesTheHitRateHasNoError) {
  CalibrationAccumulator a;
  // Bin [0.9, 1]: 10 frames at 0.9, 9 right. Bin [0.3, 0.4): 10 at 0.3, 3 right.
  for (int k = 0; k < 10; ++k) a.add(0.9, k < 9);
  for (int k = 0; k < 10; ++k) a.add(0.3, k < 3);
  EXPECT_NEAR(a.expected_calibration_error(), 0.0, 1e-12);
  const ReliabilityDiagram d = a.diagram();
  EXPECT_EQ(d[9].frames, 10);
  EXPECT_NEAR(d[9].mean_confidence, 0.9, 1e-12);
  EXPECT_NEAR(d[9].accuracy, 0.9, 1e-12);
  EXPECT_EQ(d[3].frames, 10);
  EXPECT_EQ(d[0].frames, 0);
}

TEST(Calibration, ErrorIsTheFrameWeightedGapPerBin) {
  CalibrationAccumulator a;
  // 30 frames claim 1.0 and are all wrong (gap 1); 10 frames claim 0.05 and are all right
  // (gap 0.95): ECE = (30 * 1 + 10 * 0.95) / 40.
  for (int k = 0; k < 30; ++k) a.add(1.0, false);
  for (int k = 0; k < 10; ++k) a.add(0.05, true);
  EXPECT_NEAR(a.expected_calibration_error(), (30.0 + 9.5) / 40.0, 1e-12);
  EXPECT_EQ(a.diagram()[9].frames, 30);  // exactly 1 falls in the last bin
  EXPECT_EQ(a.diagram()[0].frames, 10);
}

TEST(Calibration, OutOfRangeAndNonFiniteConfidenceAreClampedNotNaN) {
  CalibrationAccumulator a;
  a.add(std::numeric_limits<double>::quiet_NaN(), false);  // a claim of nothing: right
  a.add(-3.0, false);
  a.add(7.0, true);
  EXPECT_EQ(a.frames(), 3);
  EXPECT_NEAR(a.expected_calibration_error(), 0.0, 1e-12);
  EXPECT_EQ(CalibrationAccumulator().expected_calibration_error(), 0.0);
}

TEST(Calibration, MergeEqualsAddingEverything) {
  CalibrationAccumulator a, b, all;
  for (int k = 0; k < 20; ++k) {
    const double c = 0.05 * k;
    const bool right = k % 3 != 0;
    (k % 2 ? a : b).add(c, right);
    all.add(c, right);
  }
  a.merge(b);
  EXPECT_NEAR(a.expected_calibration_error(), all.expected_calibration_error(), 1e-12);
  EXPECT_EQ(a.frames(), all.frames());
}

TEST(Calibration, MetricsScoreConfidenceAgainstWithin100msOnScoredFrames) {
  constexpr double kFps = 60.0;
  std::vector<TruthFrame> truth;
  std::vector<double> times;
  std::vector<FrameEstimate> estimates;
  for (int k = 0; k < 100; ++k) {
    truth.push_back({0, static_cast<double>(k), k >= 90, false});  // last 10: a pause, unscored
    times.push_back(k / kFps);
    FrameEstimate e{0, k < 40 ? k + 30 : k, false, false, 0.0};    // first 40: 500 ms off
    e.confidence = 0.95f;
    estimates.push_back(e);
  }
  MetricsAccumulator m;
  m.add(truth, times, estimates, kFps);
  const Metrics s = m.summary();
  // 90 scored frames claim 0.95; 50 of them are right.
  EXPECT_NEAR(s.confidence_ece, 0.95 - 50.0 / 90.0, 1e-6);
  EXPECT_EQ(s.reliability[9].frames, 90);
}

}  // namespace
}  // namespace duet
