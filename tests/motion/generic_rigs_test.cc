// Rigs of another build (generic_rigs.h): each is a valid skeleton of the height it claims, role
// detection finds every role on it from the names alone (the joints a user's file of that kind
// would name), written as a centimetre Z-up BVH it loads back at its size, and a real salsa take
// retargeted onto it keeps the role directions within 2 degrees.
#include "duet/motion/generic_rigs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "duet/io/bvh.h"
#include "duet/io/motion_file.h"
#include "duet/math/rotation.h"
#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/retarget.h"
#include "duet/motion/role_detection.h"
#include "duet/motion/up_axis.h"
#include "motion/role_directions.h"

namespace duet {
namespace {

struct Expected {
  GenericRig rig;
  double height_m;
  // A few roles and the joint that must play them: the traps of each kind of rig (a clavicle
  // named "shoulder", twist helpers beside the limb joints, a spine with more joints).
  std::map<Role, std::string> joints;
};

const Expected kExpected[] = {
    {GenericRig::kGameAvatar,
     1.80,
     {{Role::kHips, "pelvis"},
      {Role::kChest, "spine_05"},
      {Role::kLeftShoulder, "upperarm_l"},
      {Role::kLeftElbow, "lowerarm_l"},
      {Role::kRightWrist, "hand_r"},
      {Role::kLeftHip, "thigh_l"},
      {Role::kRightKnee, "calf_r"},
      {Role::kLeftToe, "ball_l"}}},
    {GenericRig::kDepthCamera,
     1.60,
     {{Role::kHips, "SpineBase"},
      {Role::kChest, "SpineShoulder"},
      {Role::kLeftShoulder, "ShoulderLeft"},
      {Role::kRightWrist, "WristRight"},
      {Role::kLeftAnkle, "AnkleLeft"},
      {Role::kRightToe, "FootRight"}}},
    {GenericRig::kInertialSuit,
     1.92,
     {{Role::kHips, "Pelvis"},
      {Role::kChest, "T8"},
      {Role::kLeftShoulder, "LeftUpperArm"},
      {Role::kRightElbow, "RightForeArm"},
      {Role::kLeftHip, "LeftUpperLeg"},
      {Role::kRightToe, "RightToe"}}},
};

std::string name_of(const Skeleton& skeleton, int joint) {
  return joint < 0 ? "(none)" : skeleton.joints[static_cast<std::size_t>(joint)].name;
}

TEST(GenericRigs, EachIsAValidBodyWhoseRolesAreFoundByName) {
  ASSERT_EQ(generic_rigs().size(), std::size(kExpected));
  for (const Expected& e : kExpected) {
    const Skeleton rig = make_generic_rig(e.rig);
    ASSERT_EQ(rig.validate(), "") << static_cast<int>(e.rig);
    const RoleDetection detection = detect_roles_report(rig);
    ASSERT_TRUE(detection.complete()) << detection.problem;
    EXPECT_EQ(detection.roles.convention, "names");
    for (const auto& [role, joint] : e.joints) {
      EXPECT_EQ(name_of(rig, detection.roles[role]), joint) << role_name(role);
    }
    const BodyDimensions body = measure_body(rig, detection.roles);
    EXPECT_NEAR(body.standing_height_m, e.height_m, 0.08) << static_cast<int>(e.rig);
  }
}

TEST(GenericRigs, ACentimetreZUpFileOfOneLoadsAtItsSize) {
  // The game avatar as an engine exports it: centimetres, Z up (offsets and all).
  Skeleton rig = make_generic_rig(GenericRig::kGameAvatar);
  const Quat y_up_to_z_up = rotation_to_y_up(UpAxis::kPosZ).conjugate();
  for (Joint& joint : rig.joints) joint.offset = y_up_to_z_up * joint.offset;
  const Clip clip(std::make_shared<const Skeleton>(rig), 30.0, 2);
  const std::string path =
      (std::filesystem::temp_directory_path() / "duet_generic_rig_avatar.bvh").string();
  BvhWriteOptions centimetres;
  centimetres.units_per_metre = 100.0;
  ASSERT_TRUE(write_bvh(clip, path, centimetres).ok());
  Result<LoadedMotion> loaded = load_motion({path});
  std::filesystem::remove(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(loaded.value().units_name, "centimetres");
  EXPECT_EQ(loaded.value().up_axis, UpAxis::kPosZ);
  EXPECT_NEAR(loaded.value().body.standing_height_m, 1.80, 0.08);
  EXPECT_EQ(name_of(loaded.value().clip.skeleton(), loaded.value().roles[Role::kLeftShoulder]),
            "upperarm_l");
}

TEST(GenericRigs, ASalsaTakeRetargetedOntoEachKeepsTheRoleDirections) {
  MotionLoadOptions at_60;
  at_60.frame_rate = 60.0;
  Result<LoadedMotion> salsa =
      load_motion({std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/60/60_01_scaled.bvh"}, at_60);
  ASSERT_TRUE(salsa.ok()) << salsa.error().message;
  const LoadedMotion& source = salsa.value();
  for (const GenericRigInfo& info : generic_rigs()) {
    auto rig = std::make_shared<const Skeleton>(make_generic_rig(info.rig));
    const JointRoles roles = detect_roles_report(*rig).roles;
    Result<Clip> out = retarget_clip(source.clip, source.roles, rig, roles);
    ASSERT_TRUE(out.ok()) << info.name << ": " << out.error().message;
    const test::Stats errors =
        test::stats(test::direction_errors(source.clip, source.roles, out.value(), roles, false));
    const double worst_deg = errors.max;
    EXPECT_LT(worst_deg, 2.0) << info.name;
  }
}

}  // namespace
}  // namespace duet
