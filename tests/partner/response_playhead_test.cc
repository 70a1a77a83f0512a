// The playhead: the response shown at a real frame that advances at the dancer's tempo, close to
// the follower's whole-frame estimate, and restarting on it at a jump.
#include "duet/partner/response_playhead.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace duet {
namespace {

constexpr double kFps = 60.0;
constexpr double kDt = 1.0 / kFps;

TEST(ResponsePlayhead, TurnsAStaircaseEstimateIntoSteadyMotion) {
  // A dancer at 0.7x: the whole-frame estimate holds and steps (round(0.7 f)); the playhead
  // advances by about 0.7 frames every frame.
  const PlayheadParams params;
  ResponsePlayhead playhead;
  std::vector<double> shown;
  double largest_raw_step = 0.0;
  for (int f = 0; f < 240; ++f) {
    const int estimate = static_cast<int>(std::lround(0.7 * f));
    shown.push_back(playhead.advance(estimate, false, 0.7, kDt, kFps, params));
    EXPECT_LE(std::abs(shown.back() - estimate), params.max_offset_frames + 1e-12);
    if (f > 0) {
      largest_raw_step = std::max(largest_raw_step,
                                  1.0 * (estimate - static_cast<int>(std::lround(0.7 * (f - 1)))));
    }
  }
  EXPECT_EQ(largest_raw_step, 1.0);
  // Second differences (acceleration in frames per frame^2): the staircase has +-1; the
  // playhead far less.
  double largest_second_difference = 0.0;
  for (std::size_t f = 60; f + 1 < shown.size(); ++f) {
    largest_second_difference =
        std::max(largest_second_difference, std::abs(shown[f + 1] - 2.0 * shown[f] + shown[f - 1]));
  }
  EXPECT_LT(largest_second_difference, 0.5);
}

TEST(ResponsePlayhead, RestartsOnTheEstimateAtAJumpAndWithoutTime) {
  const PlayheadParams params;
  ResponsePlayhead playhead;
  EXPECT_EQ(playhead.advance(100, false, 1.0, kDt, kFps, params), 100.0);  // first frame
  EXPECT_NEAR(playhead.advance(101, false, 1.0, kDt, kFps, params), 101.0, 1e-12);
  EXPECT_EQ(playhead.advance(900, true, 1.0, kDt, kFps, params), 900.0);   // jump
  EXPECT_EQ(playhead.advance(905, false, 1.0, 0.0, kFps, params), 905.0);  // no dt
  EXPECT_EQ(playhead.advance(906, false, 1.0, std::nan(""), kFps, params), 906.0);
  // A non-finite or non-positive tempo counts as 1; the result stays near the estimate.
  const double p = playhead.advance(907, false, std::nan(""), kDt, kFps, params);
  EXPECT_NEAR(p, 907.0, 1e-9);
  // An estimate far ahead without a jump: the playhead never trails it by more than the limit.
  EXPECT_NEAR(playhead.advance(950, false, 1.0, kDt, kFps, params),
              950.0 - params.max_offset_frames, 1e-12);
  playhead.reset();
  EXPECT_EQ(playhead.advance(3, false, 1.0, kDt, kFps, params), 3.0);
}

TEST(PlayheadParams, Validate) {
  PlayheadParams p;
  EXPECT_STREQ(p.validate(), "");
  p.pull_half_life_s = -1.0;
  EXPECT_NE(std::string(p.validate()).find("pull_half_life_s"), std::string::npos);
  p = PlayheadParams{};
  p.max_offset_frames = std::nan("");
  EXPECT_NE(std::string(p.validate()).find("max_offset_frames"), std::string::npos);
}

}  // namespace
}  // namespace duet
