// Issue 11 (calibrated confidence): a frame flagged lost is not trusted as a followed frame is.
#include "duet/live/lost_confidence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "duet/eval/performance.h"
#include "duet/follow/hmm_follower.h"
#include "duet/live/young_offset_confidence.h"
#include "duet/motion/head_hands.h"
#include "live/salsa_library.h"

namespace duet {
namespace {

constexpr InputPoints kInputs[] = {InputPoints::kFullBody, InputPoints::kHeadHands};

TEST(LostConfidence, IsAProbabilityMonotoneInTheConfidence) {
  for (const InputPoints points : kInputs) {
    float previous = -1.0f;
    for (int i = 0; i <= 1000; ++i) {
      const float p = LostConfidence::apply(static_cast<float>(i) / 1000.0f, points);
      ASSERT_GE(p, 0.0f);
      ASSERT_LE(p, 1.0f);
      ASSERT_GE(p, previous) << "at " << i;
      previous = p;
    }
  }
}

TEST(LostConfidence, NonFiniteInputGivesAProbability) {
  constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (const InputPoints points : kInputs) {
    for (const float p : {LostConfidence::apply(kNan, points), LostConfidence::apply(kInf, points),
                          LostConfidence::apply(-kInf, points)}) {
      EXPECT_TRUE(std::isfinite(p));
      EXPECT_GE(p, 0.0f);
      EXPECT_LE(p, 1.0f);
    }
  }
}

TEST(LostConfidence, ALostFrameIsNotTrustedWhole) {
  // What the fit found (docs/evaluation.md, "Confidence on a lost frame"): three points' lost
  // frames claiming 0.9 were right on about a third of them.
  EXPECT_LT(LostConfidence::apply(0.9f, InputPoints::kHeadHands), 0.5f);
  EXPECT_LT(LostConfidence::apply(0.9f, InputPoints::kFullBody), 0.8f);
}

// Take 01 from the real CMU ASF/AMC as three points, uncalibrated: its lost frames claimed far
// more than they were right; with their confidence mapped the claim is near the share right.
TEST(LostConfidence, ALostFramesClaimIsNearTheShareRightOnAnotherRig) {
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  Result<LoadedMotion> take = load_motion({test::kSalsaData + "/cmu-salsa/asf-amc/60.asf",
                                           test::kSalsaData + "/cmu-salsa/asf-amc/60_01.amc"},
                                          options);
  ASSERT_TRUE(take) << take.error().message;
  // As a headset reports it under noise: 1 cm and 4 degrees per point.
  Performance performance;
  performance.motion = take.value().clip;
  performance.roles = take.value().roles;
  PointNoiseOptions noise;
  noise.position_m = 0.01;
  noise.rotation_deg = 4.0;
  Result<Performance> points = with_head_hands(std::move(performance), noise);
  ASSERT_TRUE(points) << points.error().message;
  const DuetLibrary& library = test::head_hands_library();
  struct Lost {
    int frames = 0, right = 0;
    double claimed = 0.0;
  };
  auto follow = [&](bool lost_confidence) {
    PostureBiasParams bias;
    bias.lost_confidence = lost_confidence;
    Result<HmmFollower> follower = HmmFollower::create(library.model(), FollowParams{});
    EXPECT_TRUE(follower) << follower.error().message;
    Result<FollowSession> session =
        FollowSession::create(library, points.value().motion.skeleton_ptr(), head_hands_roles(),
                              std::make_unique<HmmFollower>(std::move(follower).value()), bias);
    EXPECT_TRUE(session) << session.error().message;
    Lost lost;
    for (int f = 0; f < points.value().motion.frame_count(); ++f) {
      const FollowResult r = session.value().step(points.value().motion.translations_ls(f),
                                                  points.value().motion.rotations_ls(f), f / 60.0);
      const float young = YoungOffsetConfidence::apply(
          r.tracker_confidence, r.rig_offset, r.rig_offset_learnt_s, InputPoints::kHeadHands);
      if (!r.lost) {
        EXPECT_EQ(r.confidence, young) << "frame " << f;
        continue;
      }
      EXPECT_EQ(r.confidence,
                lost_confidence ? LostConfidence::apply(young, InputPoints::kHeadHands) : young)
          << "frame " << f;
      ++lost.frames;
      lost.right += (r.take == 0 && std::abs(r.frame_in_take - f) <= 6) ? 1 : 0;
      lost.claimed += r.confidence;
    }
    return lost;
  };
  const Lost as_was = follow(false);
  const Lost mapped = follow(true);
  ASSERT_GT(as_was.frames, 50);
  ASSERT_EQ(as_was.frames, mapped.frames);  // the map changes the confidence only
  const double right = static_cast<double>(mapped.right) / mapped.frames;
  std::printf(
      "ASF take 01 as three points, %d lost frames: %.1f%% right, claimed %.1f%% -> %.1f%%\n",
      mapped.frames, 100.0 * right, 100.0 * as_was.claimed / as_was.frames,
      100.0 * mapped.claimed / mapped.frames);
  EXPECT_LT(std::abs(mapped.claimed / mapped.frames - right),
            0.5 * std::abs(as_was.claimed / as_was.frames - right));
}

}  // namespace
}  // namespace duet
