#include "duet/math/lookup_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace duet {
namespace {

TEST(LookupTable, BandsAreHalfOpenFromEachEdge) {
  const float edges[] = {1.0f, 2.0f, 5.0f};
  EXPECT_EQ(band_of(-3.0f, edges), 0);
  EXPECT_EQ(band_of(0.999f, edges), 0);
  EXPECT_EQ(band_of(1.0f, edges), 1);
  EXPECT_EQ(band_of(4.9f, edges), 2);
  EXPECT_EQ(band_of(5.0f, edges), 3);
  EXPECT_EQ(band_of(std::numeric_limits<float>::infinity(), edges), 3);
  EXPECT_EQ(band_of(std::nanf(""), edges), 0);
}

TEST(LookupTable, InterpolatesBetweenKnotsAndHoldsTheEnds) {
  const float knots[] = {0.0f, 0.5f, 1.0f};
  const float values[] = {0.2f, 0.4f, 1.0f};
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 0.0f), 0.2f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 0.25f), 0.3f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 0.5f), 0.4f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 0.75f), 0.7f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 1.0f), 1.0f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, -1.0f), 0.2f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 2.0f), 1.0f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, std::nanf("")), 0.2f);
}

TEST(LookupTable, ARepeatedKnotIsAStepAndEachSideReadsItsOwnValue) {
  // As scripts/fit_confidence_calibration.py writes its table: 0.9 twice.
  const float knots[] = {0.8f, 0.9f, 0.9f, 0.91f};
  const float values[] = {0.5f, 0.6f, 0.6f, 0.9f};
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 0.85f), 0.55f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 0.9f), 0.6f);
  EXPECT_NEAR(interpolate_knots(knots, values, 0.905f), 0.75f, 1e-5f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 0.91f), 0.9f);
}

TEST(LookupTable, ResultsAreProbabilities) {
  const float knots[] = {0.0f, 1.0f};
  const float values[] = {-0.5f, 1.5f};
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 0.0f), 0.0f);
  EXPECT_FLOAT_EQ(interpolate_knots(knots, values, 1.0f), 1.0f);
}

}  // namespace
}  // namespace duet
