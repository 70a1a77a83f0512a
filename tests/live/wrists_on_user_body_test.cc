#include "duet/live/wrists_on_user_body.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "../features/synthetic_dancer.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/partner/alignment.h"

namespace duet {
namespace {

using testing::daz_roles;
using testing::make_dance;
using testing::make_role_skeleton;

LoadedMotion synthetic_dancer() {
  auto skeleton = make_role_skeleton();
  LoadedMotion dancer;
  dancer.clip = make_dance(skeleton, 60.0, 240);
  dancer.roles = daz_roles(*skeleton);
  return dancer;
}

SourceSkeleton user_of(std::shared_ptr<const Skeleton> skeleton) {
  SourceSkeleton user;
  user.roles = daz_roles(*skeleton);
  user.skeleton = std::move(skeleton);
  return user;
}

TEST(WristsOnUserBody, TheTemplatesOwnBodyChangesNothing) {
  const LoadedMotion dancer = synthetic_dancer();
  Result<WristsOnUserBody> wrists =
      WristsOnUserBody::create({&dancer}, user_of(dancer.clip.skeleton_ptr()));
  ASSERT_TRUE(wrists) << wrists.error().message;
  for (const double frame : {0.0, 17.5, 100.0, 239.0}) {
    for (const Vec3& difference : wrists.value().wrist_difference_hs(0, frame)) {
      EXPECT_LT(difference.norm(), 1e-9) << "frame " << frame;
    }
  }
}

TEST(WristsOnUserBody, LongerArmsReachFurtherAlongTheArm) {
  // A user whose upper arms and forearms are 1.2x the dancer's: in the same pose each wrist lies
  // 0.2x the dancer's shoulder -> wrist further along it, in the body's heading frame.
  const LoadedMotion dancer = synthetic_dancer();
  auto longer = std::make_shared<Skeleton>(dancer.clip.skeleton());
  for (const Role role :
       {Role::kLeftElbow, Role::kLeftWrist, Role::kRightElbow, Role::kRightWrist}) {
    longer->joints[static_cast<std::size_t>(dancer.roles[role])].offset *= 1.2;
  }
  Result<WristsOnUserBody> wrists = WristsOnUserBody::create({&dancer}, user_of(longer));
  ASSERT_TRUE(wrists) << wrists.error().message;
  const auto joints = static_cast<std::size_t>(dancer.clip.joint_count());
  std::vector<Vec3> positions(joints);
  std::vector<Quat> rotations(joints);
  double largest_m = 0.0;
  for (const int frame : {0, 40, 120, 239}) {
    forward_kinematics(dancer.clip.skeleton(), dancer.clip.translations_ls(frame),
                       dancer.clip.rotations_ls(frame), positions, rotations);
    const Transform to_heading = body_heading_frame(positions, dancer.roles).inverse();
    const std::array<Vec3, 2> differences = wrists.value().wrist_difference_hs(0, frame);
    const Role shoulders[2] = {Role::kLeftShoulder, Role::kRightShoulder};
    const Role wrist_roles[2] = {Role::kLeftWrist, Role::kRightWrist};
    for (std::size_t side = 0; side < 2; ++side) {
      const Vec3 arm_ws = positions[static_cast<std::size_t>(dancer.roles[wrist_roles[side]])] -
                          positions[static_cast<std::size_t>(dancer.roles[shoulders[side]])];
      const Vec3 expected = 0.2 * (to_heading.rotation * arm_ws);
      EXPECT_LT((differences[side] - expected).norm(), 1e-3) << "frame " << frame;
      largest_m = std::max(largest_m, differences[side].norm());
    }
  }
  EXPECT_GT(largest_m, 0.05);  // the arms are 0.53 m: a tenth of a metre, not nothing
}

TEST(WristsOnUserBody, ATakeOutOfRangeIsNoDifference) {
  const LoadedMotion dancer = synthetic_dancer();
  Result<WristsOnUserBody> wrists =
      WristsOnUserBody::create({&dancer}, user_of(dancer.clip.skeleton_ptr()));
  ASSERT_TRUE(wrists);
  for (const int take : {-1, 1}) {
    for (const Vec3& difference : wrists.value().wrist_difference_hs(take, 0.0)) {
      EXPECT_TRUE(difference.isZero());
    }
  }
}

TEST(WristsOnUserBody, ASkeletonWithoutArmsIsAnError) {
  const LoadedMotion dancer = synthetic_dancer();
  SourceSkeleton user = user_of(dancer.clip.skeleton_ptr());
  user.roles.joints[static_cast<std::size_t>(Role::kLeftElbow)] = -1;
  Result<WristsOnUserBody> wrists = WristsOnUserBody::create({&dancer}, user);
  ASSERT_FALSE(wrists);
  EXPECT_NE(wrists.error().message.find("user"), std::string::npos) << wrists.error().message;
}

}  // namespace
}  // namespace duet
