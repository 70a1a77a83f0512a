#include "duet/live/calibration_advice.h"

#include <gtest/gtest.h>

namespace duet {
namespace {

FollowResult frame_with_offset(float offset, float learnt_s) {
  FollowResult r;
  r.rig_offset = offset;
  r.rig_offset_learnt_s = learnt_s;
  return r;
}

constexpr double kDt = 1.0 / 60.0;

TEST(CalibrationAdvice, AnotherBodysOffsetIsAdvisedOnceASecondOfSettledFramesIsIn) {
  CalibrationAdvice advice;
  // Frames whose offset is young do not count, whatever their size.
  for (int i = 0; i < 600; ++i) advice.observe(frame_with_offset(0.3f, 1.0f), kDt);
  EXPECT_FALSE(advice.other_body_offset());
  for (int i = 0; i < 59; ++i) advice.observe(frame_with_offset(0.094f, 5.0f), kDt);
  EXPECT_FALSE(advice.other_body_offset()) << "under a second of settled frames";
  advice.observe(frame_with_offset(0.094f, 5.0f), kDt);
  ASSERT_TRUE(advice.other_body_offset());
  EXPECT_NEAR(*advice.other_body_offset(), 0.094f, CalibrationAdvice::kResolution);
  advice.reset();
  EXPECT_FALSE(advice.other_body_offset());
}

TEST(CalibrationAdvice, TheMedianDecidesNotAFewLargeOffsets) {
  CalibrationAdvice advice;
  // The library's own body (0.006-0.02) with a third of its frames far off: no advice.
  for (int i = 0; i < 120; ++i) advice.observe(frame_with_offset(0.015f, 6.0f), kDt);
  for (int i = 0; i < 60; ++i) advice.observe(frame_with_offset(0.5f, 6.0f), kDt);
  EXPECT_FALSE(advice.other_body_offset());
  // Past half the frames at another body's offset: advised, at the median.
  for (int i = 0; i < 61; ++i) advice.observe(frame_with_offset(0.08f, 6.0f), kDt);
  ASSERT_TRUE(advice.other_body_offset());
  EXPECT_NEAR(*advice.other_body_offset(), 0.08f, CalibrationAdvice::kResolution);
}

TEST(CalibrationAdvice, FramesWithoutEvidenceOrTimeOrAFiniteOffsetCountNothing) {
  CalibrationAdvice advice;
  FollowResult missing = frame_with_offset(0.1f, 6.0f);
  missing.missing = true;
  for (int i = 0; i < 120; ++i) {
    advice.observe(missing, kDt);
    advice.observe(frame_with_offset(0.1f, 6.0f), 0.0);
    advice.observe(frame_with_offset(std::numeric_limits<float>::quiet_NaN(), 6.0f), kDt);
    advice.observe(frame_with_offset(0.1f, std::numeric_limits<float>::quiet_NaN()), kDt);
  }
  EXPECT_FALSE(advice.other_body_offset());
  // Offsets past the histogram's top count in its last bin.
  for (int i = 0; i < 60; ++i) advice.observe(frame_with_offset(7.0f, 6.0f), kDt);
  ASSERT_TRUE(advice.other_body_offset());
  EXPECT_GT(*advice.other_body_offset(), 0.99f);
}

}  // namespace
}  // namespace duet
