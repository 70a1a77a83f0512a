// Spatial alignment: the partner keeps its captured place relative to the template dancer,
// wherever the user stands and faces.
#include "duet/partner/alignment.h"

#include <gtest/gtest.h>

#include <cmath>

#include "duet/math/rotation.h"
#include "partner/synthetic_partner.h"

namespace duet {
namespace {

TEST(HeadingFrame, ProjectsOnTheFloorAndKeepsOnlyTheYaw) {
  const Quat tilted = yaw_rotation(0.8) * quat_from_axis_angle(Vec3::UnitX(), 0.3);
  const Transform h = heading_frame(Vec3(1.0, 0.9, -2.0), tilted);
  EXPECT_TRUE(h.translation.isApprox(Vec3(1.0, 0.0, -2.0)));
  EXPECT_NEAR(heading_yaw(h.rotation), 0.8, 1e-9);
  EXPECT_NEAR((h.rotation * Vec3::UnitY() - Vec3::UnitY()).norm(), 0.0, 1e-12);
}

TEST(SpatialAlignment, StoresTheResponseRootInTheTemplateHeadingFrame) {
  const auto skeleton = test::make_humanoid();
  Clip leader = test::make_standing_clip(skeleton, 3);
  Clip follower = test::make_standing_clip(skeleton, 3);
  // The follower stands 0.8 m in front of the leader, facing him, at every frame, while the
  // pair moves and turns in the room.
  for (int f = 0; f < 3; ++f) {
    const double yaw = 0.7 * f - 1.0;
    const Vec3 leader_at(2.0 * f, 0.95 + 0.01 * f, -1.0 * f);
    test::set_root(leader, f, leader_at, yaw);
    test::set_root(follower, f, leader_at + yaw_rotation(yaw) * Vec3(0, 0, 0.8) + Vec3(0, 0.02, 0),
                   yaw + kPi);
  }
  const Result<SpatialAlignment> alignment = SpatialAlignment::build(leader, follower);
  ASSERT_TRUE(alignment.ok()) << alignment.error().message;
  for (int f = 0; f < 3; ++f) {
    const RootPlacement& p = alignment.value().placement(f);
    EXPECT_NEAR(p.position_hs.x(), 0.0, 1e-12);
    EXPECT_NEAR(p.position_hs.z(), 0.8, 1e-12);
    EXPECT_NEAR(p.position_hs.y(), 0.97 + 0.01 * f, 1e-12);  // height above the floor
    EXPECT_NEAR(std::abs(p.relative_yaw_rad()), kPi, 1e-9);
  }
  // Between frames the placement is interpolated; outside the clip it is clamped.
  const RootPlacement half = alignment.value().placement_at(1.5);
  EXPECT_NEAR(half.position_hs.y(), 0.985, 1e-12);
  EXPECT_NEAR(half.position_hs.z(), 0.8, 1e-12);
  EXPECT_NEAR(alignment.value().placement_at(-3.0).position_hs.y(), 0.97, 1e-12);
  EXPECT_NEAR(alignment.value().placement_at(9.0).position_hs.y(), 0.99, 1e-12);
  EXPECT_NEAR(alignment.value().placement_at(std::nan("")).position_hs.y(), 0.97, 1e-12);
  // The template's own heading frame, what the placements are relative to: at frames, between
  // them (yaw -0.3 -> 0.4: 0.05 at 1.5), and clamped outside.
  for (int f = 0; f < 3; ++f) {
    const Transform h = alignment.value().template_heading_at(f);
    EXPECT_TRUE(h.translation.isApprox(Vec3(2.0 * f, 0.0, -1.0 * f))) << f;
    EXPECT_NEAR(heading_yaw(h.rotation), 0.7 * f - 1.0, 1e-9) << f;
  }
  const Transform between = alignment.value().template_heading_at(1.5);
  EXPECT_TRUE(between.translation.isApprox(Vec3(3.0, 0.0, -1.5)));
  EXPECT_NEAR(heading_yaw(between.rotation), 0.05, 1e-9);
  EXPECT_NEAR(heading_yaw(alignment.value().template_heading_at(-3.0).rotation), -1.0, 1e-9);
}

TEST(SpatialAlignment, PartnerKeepsItsRelativePlaceWhenTheUserMovesAndTurns) {
  const auto skeleton = test::make_humanoid();
  Clip leader = test::make_standing_clip(skeleton, 1);
  Clip follower = test::make_standing_clip(skeleton, 1);
  test::set_root(leader, 0, Vec3(0.3, 0.95, 0.2), 0.4);
  // Follower in front-left of the leader, turned, a little tilted.
  follower.translations_ls(0)[0] = Vec3(0.3, 0.93, 0.2) + yaw_rotation(0.4) * Vec3(0.2, 0, 0.7);
  follower.rotations_ls(0)[0] = yaw_rotation(0.4 + 2.5) * quat_from_axis_angle(Vec3::UnitX(), 0.1);
  const SpatialAlignment alignment = SpatialAlignment::build(leader, follower).value();
  const RootPlacement& p = alignment.placement(0);

  // Captured relation: follower root in the leader's heading frame.
  const Transform captured_rel =
      heading_frame(leader.translations_ls(0)[0], leader.rotations_ls(0)[0]).inverse() *
      Transform{follower.rotations_ls(0)[0], follower.translations_ls(0)[0]};

  // The user dances the leader's motion elsewhere in the room, facing elsewhere.
  for (const double user_yaw : {-2.9, -1.0, 0.0, 1.3, 3.1}) {
    for (const Vec3& user_at : {Vec3(0, 0.9, 0), Vec3(5.0, 1.0, -3.0), Vec3(-12.0, 0.9, 7.5)}) {
      const Quat user_rotation = yaw_rotation(user_yaw) * quat_from_axis_angle(Vec3::UnitX(), 0.05);
      const Transform partner = place_root(p, user_at, user_rotation);
      const Transform rel = heading_frame(user_at, user_rotation).inverse() * partner;
      EXPECT_LT((rel.translation - captured_rel.translation).norm(), 1e-12);
      EXPECT_LT(rel.rotation.angularDistance(captured_rel.rotation), 1e-9);
      // Horizontal distance between the two roots is the captured one; height is absolute.
      const Vec3 d = partner.translation - user_at;
      EXPECT_NEAR(std::hypot(d.x(), d.z()), std::hypot(0.2, 0.7), 1e-12);
      EXPECT_NEAR(partner.translation.y(), 0.93, 1e-12);
      EXPECT_NEAR(wrap_angle(heading_yaw(partner.rotation) - user_yaw), wrap_angle(2.5), 1e-9);
    }
  }
}

TEST(SpatialAlignment, RejectsClipsOfDifferentLengths) {
  const auto skeleton = test::make_humanoid();
  const Result<SpatialAlignment> r = SpatialAlignment::build(test::make_standing_clip(skeleton, 3),
                                                             test::make_standing_clip(skeleton, 4));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("3 frames"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace duet
