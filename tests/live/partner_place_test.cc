// PartnerPlace: where in the library the partner dances while the follower follows, is lost and
// finds the dancer again.
#include "duet/live/partner_place.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "partner/synthetic_partner.h"

namespace duet {
namespace {

// Two takes of a dancer standing, 600 frames at 60 Hz each.
std::vector<PartnerModel> two_takes() {
  const std::shared_ptr<const Skeleton> skeleton = test::make_humanoid();
  const Clip clip = test::make_standing_clip(skeleton, 600);
  const JointRoles roles = test::humanoid_roles(*skeleton);
  std::vector<PartnerModel> models;
  for (int k = 0; k < 2; ++k) {
    Result<PartnerModel> model = PartnerModel::build(clip, roles, clip, roles);
    EXPECT_TRUE(model) << model.error().message;
    models.push_back(std::move(model).value());
  }
  return models;
}

FollowResult estimate(int take, int frame, bool lost = false) {
  FollowResult r;
  r.take = take;
  r.frame_in_take = frame;
  r.lost = lost;
  r.steps = 1;
  r.tempo = 1.0f;
  return r;
}

constexpr double kDt = 1.0 / 60.0;

TEST(PartnerPlace, FollowsTheEstimateAndCoastsThroughALossAfterItsDelay) {
  const std::vector<PartnerModel> models = two_takes();
  PlayheadParams params;  // coast_after_lost_s 0.1
  PartnerPlace place;
  for (int f = 100; f < 110; ++f) {
    const PartnerPlaceStep step = place.next(estimate(0, f), kDt, models, params);
    EXPECT_EQ(step.take, 0);
    EXPECT_EQ(step.frame, f);
    EXPECT_FALSE(step.jumped);
  }
  // Lost for 0.5 s, the estimate hopping between the takes: for the first 0.1 s the partner goes
  // where it hops (a jump each time), then it dances on a frame at a time from there.
  int coasted = -1;
  for (int k = 0; k < 30; ++k) {
    const int hop_take = k % 2;
    const PartnerPlaceStep step =
        place.next(estimate(hop_take, 300 + 100 * hop_take + k, true), kDt, models, params);
    if (k >= 6) {
      ASSERT_TRUE(step.coasting) << k;
      EXPECT_FALSE(step.jumped) << k;
      if (coasted >= 0) {
        EXPECT_EQ(step.frame, coasted + 1) << k;
      }
      coasted = step.frame;
    }
  }
  // Found again next to where the partner danced on to: no jump; elsewhere: a jump.
  // (While it coasts, the follower's place between frames is not the partner's.)
  PartnerPlace same = place;
  const int take = place.next(estimate(0, 0, true), kDt, models, params).take;
  PartnerPlaceStep found = same.next(estimate(take, coasted + 2), kDt, models, params);
  EXPECT_FALSE(found.coasting);
  EXPECT_FALSE(found.jumped);
  found = place.next(estimate(1 - take, coasted), kDt, models, params);
  EXPECT_TRUE(found.jumped);
}

TEST(PartnerPlace, TheEstimatesPlaceBetweenFramesIsPassedOnUnlessThePartnerCoasts) {
  const std::vector<PartnerModel> models = two_takes();
  PlayheadParams params;
  PartnerPlace place;
  FollowResult r = estimate(0, 100);
  r.frame_offset = 0.4f;
  EXPECT_NEAR(place.next(r, kDt, models, params).frame_offset, 0.4, 1e-6);
  r.frame_in_take = 101;
  r.frame_offset = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(place.next(r, kDt, models, params).frame_offset, 0.0);
  // Lost long enough to coast: the partner dances on by itself, at whole frames of its own.
  r.lost = true;
  r.frame_offset = -0.3f;
  PartnerPlaceStep step;
  for (int k = 0; k < 12; ++k) step = place.next(r, kDt, models, params);
  ASSERT_TRUE(step.coasting);
  EXPECT_EQ(step.frame_offset, 0.0);
}

TEST(PartnerPlace, ADancerLostForStandingStillIsWaitedWith) {
  const std::vector<PartnerModel> models = two_takes();
  const PlayheadParams params;
  PartnerPlace place;
  for (int f = 100; f < 110; ++f) place.next(estimate(0, f), kDt, models, params);
  // Lost for a second only because the estimate holds frame 110 (FollowResult::held_still): the
  // partner holds it too, where a spell lost by distance would have it dance on.
  FollowResult held = estimate(0, 110, true);
  held.held_still = true;
  for (int k = 0; k < 60; ++k) {
    const PartnerPlaceStep step = place.next(held, kDt, models, params);
    EXPECT_FALSE(step.coasting) << k;
    EXPECT_FALSE(step.jumped) << k;
    EXPECT_EQ(step.frame, 110) << k;
  }
  PartnerPlace lost = place;
  PartnerPlaceStep step{};
  for (int k = 0; k < 60; ++k) step = lost.next(estimate(0, 110, true), kDt, models, params);
  EXPECT_TRUE(step.coasting);
  EXPECT_GT(step.frame, 150);
}

TEST(PartnerPlace, AFarMoveTheFollowerDoesNotCallAJumpRestartsThePartner) {
  const std::vector<PartnerModel> models = two_takes();
  PlayheadParams params;
  params.coast_after_lost_s = std::numeric_limits<double>::infinity();
  PartnerPlace place;
  EXPECT_FALSE(place.next(estimate(0, 100), kDt, models, params).jumped);  // the first frame
  EXPECT_FALSE(place.next(estimate(0, 102), kDt, models, params).jumped);  // within the band
  EXPECT_FALSE(place.next(estimate(0, 99), kDt, models, params).jumped);   // jitter back
  // A catch-up the follower does not call a jump (up to 2n + 6 frames) is blended, not played
  // at 6x the tempo; at 30 Hz (two template steps a frame) the same move is 4 frames ahead: kept.
  EXPECT_TRUE(place.next(estimate(0, 105), kDt, models, params).jumped);
  FollowResult thirty_hz = estimate(0, 111);
  thirty_hz.steps = 2;
  EXPECT_FALSE(place.next(thirty_hz, 2 * kDt, models, params).jumped);
  EXPECT_TRUE(place.next(estimate(0, 300), kDt, models, params).jumped);   // far: a look-alike
  EXPECT_TRUE(place.next(estimate(1, 301), kDt, models, params).jumped);   // another take
  // No estimate: the partner stays where it was.
  const PartnerPlaceStep none = place.next(estimate(-1, -1), kDt, models, params);
  EXPECT_EQ(none.take, 1);
  EXPECT_EQ(none.frame, 301);
  EXPECT_FALSE(none.jumped);
}

}  // namespace
}  // namespace duet
