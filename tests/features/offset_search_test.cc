#include "duet/features/offset_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "duet/features/posture_bias.h"

namespace duet {
namespace {

// Feature vectors of 6 dimensions: posture [0, 4), velocity [4, 6).
constexpr int kDims = 6;
constexpr double kDt = 1.0 / 60.0;
constexpr float kLimit = 0.014f;  // the learning gate of a steady sensor, about

// A template row that moves with the frame (a dance), or stands (a stance).
std::vector<float> template_row(int frame, bool moving) {
  const double t = moving ? frame * kDt : 0.0;
  return {static_cast<float>(std::sin(2.0 * t)),
          static_cast<float>(std::cos(1.5 * t)),
          static_cast<float>(0.5 * std::sin(3.0 * t + 1.0)),
          0.2f,
          static_cast<float>(0.3 * std::cos(2.0 * t)),
          0.1f};
}

const std::vector<float> kOffset = {0.3f, -0.2f, 0.15f, -0.25f};

// The input: the template row plus the rig's offset on the posture block.
std::vector<float> offset_input(const std::vector<float>& row) {
  std::vector<float> x = row;
  for (std::size_t d = 0; d < kOffset.size(); ++d) x[d] += kOffset[d];
  return x;
}

// Frames until the search adopts (-1: not within `frames`).
template <typename Frame>
int frames_to_adopt(OffsetSearch& search, int frames, Frame frame) {
  for (int f = 0; f < frames; ++f) {
    const auto [input, matched, continues] = frame(f);
    if (search.observe(input, matched, continues, kLimit, kDt, {})) return f;
  }
  return -1;
}

TEST(OffsetSearch, AdoptsADancesConstantOffsetAfterTheHold) {
  OffsetSearch search(0, 4, kDims);
  const int adopted = frames_to_adopt(search, 600, [](int f) {
    const std::vector<float> row = template_row(f, true);
    return std::tuple(offset_input(row), row, f > 0);
  });
  // The hold is 1 s of frames whose distance, the trial removed, is within the gate; the trial
  // needs a few frames to come close first.
  ASSERT_GE(adopted, 60);
  EXPECT_LE(adopted, 120);
  for (std::size_t d = 0; d < kOffset.size(); ++d) {
    EXPECT_NEAR(search.offset()[d], kOffset[d], 0.01f) << "dimension " << d;
  }
  EXPECT_GE(search.held_s(), 1.0);
}

TEST(OffsetSearch, AStanceIsNoEvidenceForAnOffset) {
  // Any offset explains a pose held still: the matched frames must move.
  OffsetSearch search(0, 4, kDims);
  EXPECT_EQ(frames_to_adopt(search, 600,
                            [](int f) {
                              const std::vector<float> row = template_row(f, false);
                              return std::tuple(offset_input(row), row, f > 0);
                            }),
            -1);
  EXPECT_LT(search.motion(), OffsetSearchParams{}.min_motion_per_dim);
  EXPECT_GE(search.held_s(), 1.0);  // explained, but it did not move
}

TEST(OffsetSearch, AResidualThatWandersIsNotAdopted) {
  // Motion the library does not hold (a walk against salsa frames): the residual changes from
  // frame to frame by more than the gate.
  OffsetSearch search(0, 4, kDims);
  std::mt19937 rng(5);
  std::normal_distribution<float> wander(0.0f, 0.2f);
  EXPECT_EQ(frames_to_adopt(search, 1200,
                            [&](int f) {
                              const std::vector<float> row = template_row(f, true);
                              std::vector<float> x = offset_input(row);
                              for (int d = 0; d < 4; ++d)
                                x[static_cast<std::size_t>(d)] += wander(rng);
                              return std::tuple(x, row, f > 0);
                            }),
            -1);
  EXPECT_GT(search.explained(), static_cast<double>(kLimit));
}

TEST(OffsetSearch, VelocitiesThatDoNotMatchAreNotExplained) {
  // The posture keeps one residual, but the body moves otherwise than the frames it is matched
  // to: the velocity block is not the offset's to remove.
  OffsetSearch search(0, 4, kDims);
  EXPECT_EQ(frames_to_adopt(search, 600,
                            [](int f) {
                              const std::vector<float> row = template_row(f, true);
                              std::vector<float> x = offset_input(row);
                              x[4] += 0.5f;
                              x[5] -= 0.5f;
                              return std::tuple(x, row, f > 0);
                            }),
            -1);
}

TEST(OffsetSearch, OnlyFramesOnAnUnbrokenPathCountTowardsTheHold) {
  OffsetSearch search(0, 4, kDims);
  EXPECT_EQ(frames_to_adopt(search, 600,
                            [](int f) {
                              const std::vector<float> row = template_row(f, true);
                              return std::tuple(offset_input(row), row, false);
                            }),
            -1);
  EXPECT_EQ(search.held_s(), 0.0);
  // A flicker now and then delays the hold but does not restart it.
  OffsetSearch flickering(0, 4, kDims);
  const int adopted = frames_to_adopt(flickering, 600, [](int f) {
    const std::vector<float> row = template_row(f, true);
    return std::tuple(offset_input(row), row, f % 10 != 0);
  });
  EXPECT_GT(adopted, 60);
  EXPECT_LT(adopted, 150);
}

TEST(OffsetSearch, NonFiniteInputCountsForNothingAndResetStartsAgain) {
  OffsetSearch search(0, 4, kDims);
  std::vector<float> bad = offset_input(template_row(0, true));
  bad[1] = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> row = template_row(0, true);
  for (int f = 0; f < 120; ++f) EXPECT_FALSE(search.observe(bad, row, true, kLimit, kDt, {}));
  EXPECT_EQ(search.held_s(), 0.0);
  EXPECT_EQ(search.offset()[0], 0.0f);
  EXPECT_FALSE(search.observe(offset_input(row), row, true, std::numeric_limits<float>::infinity(),
                              kDt, {}));
  EXPECT_FALSE(search.observe(offset_input(row), row, true, kLimit, 0.0, {}));
  EXPECT_EQ(search.held_s(), 0.0);

  ASSERT_GE(frames_to_adopt(search, 600,
                            [](int f) {
                              const std::vector<float> r = template_row(f, true);
                              return std::tuple(offset_input(r), r, f > 0);
                            }),
            0);
  search.reset();
  EXPECT_EQ(search.held_s(), 0.0);
  EXPECT_EQ(search.offset()[0], 0.0f);
  OffsetSearchParams off;
  off.enabled = false;
  EXPECT_FALSE(search.observe(offset_input(row), row, true, kLimit, kDt, off));
}

TEST(PostureBias, AnAdoptedOffsetIsRemovedAndItsLostRunStartsAgain) {
  PostureBiasParams params;
  PostureBias bias(0, 4, params);
  // Lost for 3.9 s, just under the release.
  for (int f = 0; f < 234; ++f) bias.note_lost(true, kDt);
  bias.adopt(kOffset, 1.0);
  EXPECT_NEAR(bias.offset_rms(), 0.2318f, 0.001f);
  EXPECT_EQ(bias.learnt_s(), 1.0);
  std::vector<float> x = offset_input(template_row(3, true));
  bias.correct(x);
  const std::vector<float> row = template_row(3, true);
  for (std::size_t d = 0; d < x.size(); ++d) EXPECT_NEAR(x[d], row[d], 1e-6f) << d;
  // Not let go at the next lost frame: the lost run started again at the adoption.
  for (int f = 0; f < 60; ++f) bias.note_lost(true, kDt);
  EXPECT_GT(bias.offset_rms(), 0.2f);
  // A wrong size or non-finite offset changes nothing.
  bias.adopt(std::vector<float>{1.0f}, 1.0);
  bias.adopt(std::vector<float>{std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f, 0.0f}, 1.0);
  EXPECT_NEAR(bias.offset_rms(), 0.2318f, 0.001f);
}

}  // namespace
}  // namespace duet
