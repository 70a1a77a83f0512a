// Issue 10 on real files: the same performance on another rig is followed against the salsa
// library as on the library's own rig, and motion that is no part of the dance is not.
#include <gtest/gtest.h>

#include <cstdio>

#include "duet/follow/hmm_follower.h"
#include "duet/io/motion_file.h"
#include "duet/live/duet_library.h"
#include "duet/live/follow_session.h"
#include "duet/live/young_offset_confidence.h"
#include "salsa_library.h"

namespace duet {
namespace {

const std::string kData = DUET_DATA_DIR;

std::vector<FollowResult> follow(const LoadedMotion& input) { return test::follow_clip(input); }

TEST(CrossRigFollow, TakeOneFromTheCmuAsfAmcIsFollowedAgainstTheSalsaLibrary) {
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  Result<LoadedMotion> input = load_motion(
      {kData + "/cmu-salsa/asf-amc/60.asf", kData + "/cmu-salsa/asf-amc/60_01.amc"}, options);
  ASSERT_TRUE(input) << input.error().message;
  const std::vector<FollowResult> results = follow(input.value());
  // Frame i of the AMC is frame i of take 01 (the library's take 0). Within 100 ms = 6 frames.
  int within = 0;
  for (std::size_t i = 0; i < results.size(); ++i) {
    within += results[i].take == 0 && std::abs(results[i].frame_in_take - static_cast<int>(i)) <= 6;
  }
  const double share = static_cast<double>(within) / static_cast<double>(results.size());
  std::printf("ASF take 01: %.1f%% within 100 ms\n", 100.0 * share);
  EXPECT_GE(share, 0.99);

  // The session reports the rig's offset it learns and both confidences: lowered while the offset
  // is young (young_offset_confidence.h), the tracker's own once it has settled.
  float learnt = 0.0f;
  int lowered = 0;
  for (const FollowResult& r : results) {
    EXPECT_GE(r.rig_offset_learnt_s, learnt);  // no lost run long enough to let it go
    learnt = r.rig_offset_learnt_s;
    if (r.rig_offset_learnt_s >= YoungOffsetConfidence::kSettledS) {
      EXPECT_EQ(r.confidence, r.tracker_confidence);
    } else {
      lowered += r.confidence < r.tracker_confidence ? 1 : 0;
    }
  }
  EXPECT_GE(learnt, YoungOffsetConfidence::kSettledS);
  EXPECT_GT(results.back().rig_offset, 0.03f);  // the ASF rig's (about 0.05 on the salsa takes)
  EXPECT_GT(lowered, 60);
}

TEST(CrossRigFollow, AWalkADanceAndAWaveOnAThirdPartyRigAreLost) {
  // Bandai clips: another studio's rig (roles from its joint names, centimetres guessed) and
  // motions that are no part of the salsa. The follower must not claim to follow them, and the
  // rig's posture offset must not learn to make them look like salsa. The wave (standing, one
  // arm waving) comes closest to salsa postures: with the fixed lost distance it was 47.9% lost;
  // the noise-scaled one, on this clean capture, holds it to what a clean dance reaches.
  for (const char* clip : {"walk", "dance-short", "byebye"}) {
    Result<LoadedMotion> input =
        load_motion({kData + "/bandai/dataset-1_" + std::string(clip) + "_normal_001.bvh"});
    ASSERT_TRUE(input) << input.error().message;
    const std::vector<FollowResult> results = follow(input.value());
    int lost = 0;
    for (const FollowResult& r : results) lost += r.lost ? 1 : 0;
    const double share = static_cast<double>(lost) / static_cast<double>(results.size());
    std::printf("Bandai %s: %.1f%% of frames lost\n", clip, 100.0 * share);
    EXPECT_GE(share, 0.95) << clip;
  }
}

}  // namespace
}  // namespace duet
