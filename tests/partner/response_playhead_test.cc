// The playhead: the response shown at a real frame that advances at the dancer's tempo, close to
// the follower's whole-frame estimate, and restarting on it at a jump.
#include "duet/partner/response_playhead.h"

#include <gtest/gtest.h>

#include <algorithm>
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
    // The staircase's steps count as a little jitter: the band widens a little.
    const double band =
        std::max(params.max_offset_frames, params.jitter_offset_factor * playhead.jitter_frames());
    EXPECT_LE(band, 1.5);
    EXPECT_LE(std::abs(shown.back() - estimate), band + 1e-12);
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

TEST(ResponsePlayhead, RidesThroughAJitteringEstimateButNotThroughAPause) {
  // A noisy sensor: the estimate advances at tempo 1 with white jitter of RMS 1 frame (-1, 0 or
  // +1 with equal odds would be 0.82; here a deterministic pseudo-random +-1.22).
  const PlayheadParams params;
  ResponsePlayhead playhead;
  unsigned state = 12345u;
  const auto jitter = [&state] {
    state = state * 1664525u + 1013904223u;
    return (state >> 31) != 0u ? 1.22 : -1.22;
  };
  std::vector<double> estimates, shown;
  for (int f = 0; f < 600; ++f) {
    const int estimate = static_cast<int>(std::lround(f + jitter()));
    estimates.push_back(estimate);
    shown.push_back(playhead.advance(estimate, false, 1.0, kDt, kFps, params));
  }
  // The measured jitter is the estimate's (rounded to whole frames: about 1.1).
  EXPECT_NEAR(playhead.jitter_frames(), 1.1, 0.3);
  // The shown frame's second differences are a fraction of the estimate's.
  const auto rms_second = [](const std::vector<double>& x) {
    double sum = 0.0;
    for (std::size_t f = 300; f + 1 < x.size(); ++f) {
      const double d = x[f + 1] - 2.0 * x[f] + x[f - 1];
      sum += d * d;
    }
    return std::sqrt(sum / static_cast<double>(x.size() - 301));
  };
  EXPECT_LT(rms_second(shown), 0.25 * rms_second(estimates));
  for (std::size_t f = 0; f < shown.size(); ++f) {
    EXPECT_LE(std::abs(shown[f] - estimates[f]), params.max_jitter_offset_frames + 1e-9);
  }

  // A dancer who pauses: the estimate stops (one second difference), then stands; no jitter.
  ResponsePlayhead paused;
  for (int f = 0; f < 600; ++f) {
    paused.advance(std::min(f, 300), false, 1.0, kDt, kFps, params);
  }
  EXPECT_LT(paused.jitter_frames(), 0.1);
  // A far correction without a jump is a move, not jitter.
  ResponsePlayhead moved;
  for (int f = 0; f < 120; ++f) moved.advance(f, false, 1.0, kDt, kFps, params);
  EXPECT_NEAR(moved.advance(400, false, 1.0, kDt, kFps, params), 400.0 - params.max_offset_frames,
              1e-9);
  EXPECT_LT(moved.jitter_frames(), 0.1);
  // With the widening off, the band is max_offset_frames whatever the jitter.
  PlayheadParams fixed;
  fixed.jitter_offset_factor = 0.0;
  ResponsePlayhead narrow;
  for (int f = 0; f < 600; ++f) {
    const double estimate = estimates[static_cast<std::size_t>(f)];
    EXPECT_LE(std::abs(narrow.advance(static_cast<int>(estimate), false, 1.0, kDt, kFps, fixed) -
                       estimate),
              fixed.max_offset_frames + 1e-9);
  }
}

TEST(PlayheadParams, Validate) {
  PlayheadParams p;
  EXPECT_STREQ(p.validate(), "");
  p.pull_half_life_s = -1.0;
  EXPECT_NE(std::string(p.validate()).find("pull_half_life_s"), std::string::npos);
  p = PlayheadParams{};
  p.max_offset_frames = std::nan("");
  EXPECT_NE(std::string(p.validate()).find("max_offset_frames"), std::string::npos);
  p = PlayheadParams{};
  p.jitter_offset_factor = -1.0;
  EXPECT_NE(std::string(p.validate()).find("jitter_offset_factor"), std::string::npos);
  p = PlayheadParams{};
  p.max_jitter_offset_frames = std::nan("");
  EXPECT_NE(std::string(p.validate()).find("max_jitter_offset_frames"), std::string::npos);
  p = PlayheadParams{};
  p.jitter_time_constant_s = 0.0;
  EXPECT_NE(std::string(p.validate()).find("jitter_time_constant_s"), std::string::npos);
}

}  // namespace
}  // namespace duet
