// UnseenUser: a user the sensor stopped reporting is carried on as the template dancer moves.
#include "duet/live/unseen_user.h"

#include <gtest/gtest.h>

#include <limits>

#include "duet/math/rotation.h"

namespace duet {
namespace {

Transform floor_frame(double yaw_deg, double x, double z) {
  return {yaw_rotation(deg_to_rad(yaw_deg)), Vec3(x, 0.0, z)};
}

UserPose user_at(const Transform& body) {
  UserPose user;
  user.body_heading = body;
  user.body_heading_valid = true;
  user.root_position_ws = body.apply(Vec3(0.0, 0.95, 0.0));
  user.root_rotation_ws = body.rotation;
  user.wrist_positions_ws = {body.apply(Vec3(0.3, 1.0, 0.3)), body.apply(Vec3(-0.3, 1.0, 0.3))};
  user.wrist_rotations_ws = {body.rotation, body.rotation};
  user.height_m = 1.7;
  return user;
}

TEST(UnseenUser, TheUserMovesAsTheTemplateDancerMovedSinceLastSeen) {
  // The template dancer takes a step of 0.5 m forward and turns 90 degrees left; the user, seen
  // last elsewhere and facing elsewhere, does the same from there, hands and all.
  const Transform template_then = floor_frame(30.0, 2.0, -1.0);
  const Transform template_now = template_then * floor_frame(90.0, 0.0, 0.5);
  const Transform body_then = floor_frame(-120.0, -3.0, 4.0);
  UnseenUser unseen;
  unseen.seen(user_at(body_then), template_then, 2);

  UserPose held = user_at(body_then);  // the stalled sensor's pose
  held.height_m = 1.8;
  ASSERT_TRUE(unseen.carry(held, template_now, 2));
  const UserPose expected = user_at(body_then * floor_frame(90.0, 0.0, 0.5));
  EXPECT_TRUE(held.body_heading_valid);
  EXPECT_LT((held.body_heading.translation - expected.body_heading.translation).norm(), 1e-9);
  EXPECT_LT(held.body_heading.rotation.angularDistance(expected.body_heading.rotation), 1e-9);
  EXPECT_LT((held.root_position_ws - expected.root_position_ws).norm(), 1e-9);
  EXPECT_LT(held.root_rotation_ws.angularDistance(expected.root_rotation_ws), 1e-9);
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_LT((held.wrist_positions_ws[s] - expected.wrist_positions_ws[s]).norm(), 1e-9);
    EXPECT_LT(held.wrist_rotations_ws[s].angularDistance(expected.wrist_rotations_ws[s]), 1e-9);
  }
  EXPECT_DOUBLE_EQ(held.height_m, 1.8);  // what is not a place stays the frame's own

  // Standing still in the dance, the user stays where last seen.
  UserPose still = user_at(floor_frame(0.0, 9.0, 9.0));
  ASSERT_TRUE(unseen.carry(still, template_then, 2));
  EXPECT_LT((still.root_position_ws - user_at(body_then).root_position_ws).norm(), 1e-9);
}

TEST(UnseenUser, AnUnseenHandIsHeldAgainstTheBodyAsSeen) {
  // Three points with the left controller out of view: it reports where it was, in the world,
  // while the body moves on (a step and a quarter turn); the hand stays where it was against the
  // body, the seen one is the frame's own.
  const Transform body_then = floor_frame(-120.0, -3.0, 4.0);
  const Transform body_now = body_then * floor_frame(90.0, 0.0, 0.5);
  UnseenUser unseen;
  UserPose sensed = user_at(body_now);
  EXPECT_FALSE(unseen.hold_hands(sensed, {true, false}));  // nothing seen yet
  unseen.seen(user_at(body_then), floor_frame(0.0, 0.0, 0.0), 0);
  sensed.wrist_positions_ws[0] = user_at(body_then).wrist_positions_ws[0];  // the held report
  sensed.wrist_positions_ws[1] += Vec3(0.0, 0.1, 0.0);                      // the seen hand moved
  const Vec3 seen_right = sensed.wrist_positions_ws[1];
  ASSERT_TRUE(unseen.hold_hands(sensed, {true, false}));
  const UserPose expected = user_at(body_now);
  EXPECT_LT((sensed.wrist_positions_ws[0] - expected.wrist_positions_ws[0]).norm(), 1e-9);
  EXPECT_LT(sensed.wrist_rotations_ws[0].angularDistance(expected.wrist_rotations_ws[0]), 1e-9);
  EXPECT_EQ(sensed.wrist_positions_ws[1], seen_right);
  EXPECT_LT((sensed.root_position_ws - expected.root_position_ws).norm(), 1e-9);
}

TEST(UnseenUser, NothingIsCarriedBeforeAUserIsSeenOrIntoAnotherTake) {
  UnseenUser unseen;
  UserPose user = user_at(floor_frame(10.0, 1.0, 1.0));
  const UserPose as_given = user;
  EXPECT_FALSE(unseen.carry(user, floor_frame(0.0, 0.0, 0.0), 0));
  unseen.seen(as_given, floor_frame(0.0, 0.0, 0.0), 0);
  EXPECT_FALSE(unseen.carry(user, floor_frame(0.0, 0.0, 1.0), 1));  // a jump while unseen
  EXPECT_EQ(user.root_position_ws, as_given.root_position_ws);
  // A user seen without a place (no finite body frame) is not remembered.
  UserPose nowhere = as_given;
  nowhere.body_heading.translation.x() = std::numeric_limits<double>::quiet_NaN();
  unseen.seen(nowhere, floor_frame(0.0, 0.0, 0.0), 0);
  EXPECT_FALSE(unseen.carry(user, floor_frame(0.0, 0.0, 1.0), 0));
  unseen.seen(as_given, floor_frame(0.0, 0.0, 0.0), 0);
  unseen.reset();
  EXPECT_FALSE(unseen.carry(user, floor_frame(0.0, 0.0, 1.0), 0));
}

}  // namespace
}  // namespace duet
