// The judge of which estimates show the user what the true frame shows, on real duets: takes
// 60_02 and 60_04 both start with their dancers standing, alike, but with the partner standing
// about 25 cm elsewhere relative to the leader.
#include "duet/eval/look_alike_frames.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "duet/eval/metrics.h"
#include "duet/live/duet_library.h"

namespace duet {
namespace {

const DuetLibrary& two_standing_starts() {
  static const DuetLibrary library = [] {
    const std::string dir = std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/";
    std::vector<PairFiles> pairs;
    for (const char* trial : {"02", "04"}) {
      pairs.push_back(
          {{dir + "60/60_" + trial + "_scaled.bvh"}, {dir + "61/61_" + trial + "_scaled.bvh"}});
    }
    LibraryOptions options;
    options.load.frame_rate = 60.0;
    Result<DuetLibrary> loaded = DuetLibrary::load(pairs, options);
    if (!loaded) throw std::runtime_error(loaded.error().message);
    return std::move(loaded).value();
  }();
  return library;
}

constexpr int k0602 = 0;
constexpr int k0604 = 1;

FrameEstimate estimate_at(int take, int frame) {
  FrameEstimate estimate;
  estimate.take = take;
  estimate.frame_in_take = frame;
  return estimate;
}

bool shows_the_same(const LookAlikeFrames& judge, int true_take, double true_frame, int take,
                    int frame) {
  return judge.shows_the_same({true_take, true_frame, false, false}, estimate_at(take, frame));
}

TEST(LookAlikeFrames, WithinTheWindowOfTheTrueFrameIsTheSame) {
  const LookAlikeFrames judge = LookAlikeFrames::build(two_standing_starts()).value();
  EXPECT_TRUE(shows_the_same(judge, k0604, 900.0, k0604, 906));
  EXPECT_TRUE(shows_the_same(judge, k0604, 900.0, k0604, 894));
  // Dancing, 0.5 s off: another pose.
  EXPECT_FALSE(shows_the_same(judge, k0604, 900.0, k0604, 930));
  EXPECT_FALSE(shows_the_same(judge, k0604, 900.0, k0602, 900));
}

TEST(LookAlikeFrames, AStillPoseHeldIsTheSameThroughoutTheHold) {
  const LookAlikeFrames judge = LookAlikeFrames::build(two_standing_starts()).value();
  // 60_04's dancers stand still over its first two seconds: 0.7 s off is the same pose and the
  // same partner.
  EXPECT_TRUE(shows_the_same(judge, k0604, 90.0, k0604, 48));
}

TEST(LookAlikeFrames, AnotherTakesStandingStartWithThePartnerElsewhereIsNot) {
  const DuetLibrary& library = two_standing_starts();
  const LookAlikeFrames judge = LookAlikeFrames::build(library).value();
  // The leader stands alike in both takes, but 61_02 stands about 25 cm from where 61_04 stands.
  EXPECT_FALSE(shows_the_same(judge, k0604, 60.0, k0602, 130));
  // Told to allow half a metre, the judge takes it for the same.
  LookAlikeOptions loose;
  loose.placement_m = 0.5;
  loose.distance_per_dim = 0.004f;
  const LookAlikeFrames lenient = LookAlikeFrames::build(library, loose).value();
  EXPECT_TRUE(shows_the_same(lenient, k0604, 60.0, k0602, 130));
}

TEST(LookAlikeFrames, AnEstimateOutsideTheLibraryIsNeverTheSame) {
  const LookAlikeFrames judge = LookAlikeFrames::build(two_standing_starts()).value();
  EXPECT_FALSE(shows_the_same(judge, k0604, 60.0, -1, -1));
  EXPECT_FALSE(shows_the_same(judge, k0604, 60.0, 2, 60));
  EXPECT_FALSE(shows_the_same(judge, k0604, 60.0, k0604, 1000000));
  EXPECT_FALSE(judge.shows_the_same({k0604, std::nan(""), false, false}, estimate_at(k0604, 60)));
}

TEST(LookAlikeFrames, MetricsCountTheLookAlikesApartFromAcc100) {
  const LookAlikeFrames judge = LookAlikeFrames::build(two_standing_starts()).value();
  // Four frames of 60_04's standing start followed 0.7 s late, then four dancing frames 0.5 s
  // late.
  std::vector<TruthFrame> truth;
  std::vector<double> times;
  std::vector<FrameEstimate> estimates;
  for (int k = 0; k < 8; ++k) {
    const int frame = k < 4 ? 90 + k : 900 + k;
    truth.push_back({k0604, static_cast<double>(frame), false, false});
    times.push_back(k / 60.0);
    estimates.push_back(estimate_at(k0604, k < 4 ? frame - 42 : frame + 30));
  }
  MetricsAccumulator with_judge;
  with_judge.add(truth, times, estimates, 60.0, &judge);
  const Metrics m = with_judge.summary();
  EXPECT_DOUBLE_EQ(m.within_100ms, 0.0);
  EXPECT_DOUBLE_EQ(m.within_100ms_alike, 0.5);
  MetricsAccumulator without;
  without.add(truth, times, estimates, 60.0);
  EXPECT_DOUBLE_EQ(without.summary().within_100ms_alike, 0.0);
}

TEST(LookAlikeFrames, ABadToleranceIsAnError) {
  LookAlikeOptions options;
  options.placement_m = -1.0;
  EXPECT_FALSE(LookAlikeFrames::build(two_standing_starts(), options));
  options = {};
  options.distance_per_dim = std::nanf("");
  EXPECT_FALSE(LookAlikeFrames::build(two_standing_starts(), options));
}

}  // namespace
}  // namespace duet
