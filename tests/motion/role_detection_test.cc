// Role detection for rigs no built-in map names: synthetic skeletons named the way Mixamo, Unity,
// Perception Neuron, SMPL and Rigify name them (with the "shoulder" = clavicle or upper-arm trap),
// real skeletons with every joint renamed (found from the hierarchy alone), and a legless rig.
#include "duet/motion/role_detection.h"

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "duet/io/bvh.h"
#include "duet/motion/up_axis.h"

namespace duet {
namespace {

// The parts of a T-posed body (facing +Z, left at +X, Y up, metres) and the name each rig gives
// them; "" leaves a part out. Left names are given; right names swap the side marker.
struct RigNames {
  std::string prefix;
  std::string hips;
  std::vector<std::string> spines;  // the last one is where arms and neck branch
  std::vector<std::string> necks;
  std::string head;
  std::string clavicle, upper_arm, forearm, hand, hand_child;  // per side, with "{}" for L/R
  std::string thigh, shin, foot, toe;
  std::string left, right;  // what replaces "{}"
  std::vector<std::string> fingers;  // finger joints under the hand
};

std::string sided(const std::string& pattern, const std::string& side) {
  std::string s = pattern;
  if (const auto at = s.find("{}"); at != std::string::npos) s.replace(at, 2, side);
  return s;
}

Skeleton build(const RigNames& n) {
  Skeleton s;
  auto add = [&](const std::string& name, int parent, Vec3 offset, bool end = false) {
    Joint j;
    j.name = name.empty() ? std::string() : n.prefix + name;
    if (end) j.name = s.joints[static_cast<std::size_t>(parent)].name + "_End";
    j.parent = parent;
    j.offset = offset;
    j.end_site = end;
    if (!end) j.channels = {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
    s.joints.push_back(j);
    return s.joint_count() - 1;
  };
  const int hips = add(n.hips, -1, Vec3(0, 1.0, 0));
  int chest = hips;
  for (const std::string& spine : n.spines) chest = add(spine, chest, Vec3(0, 0.12, 0));
  int top = chest;
  for (const std::string& neck : n.necks) top = add(neck, top, Vec3(0, 0.08, 0));
  add("", add(n.head, top, Vec3(0, 0.1, 0)), Vec3(0, 0.15, 0), true);
  for (int k = 0; k < 2; ++k) {
    const double x = k == 0 ? 1.0 : -1.0;
    const std::string& side = k == 0 ? n.left : n.right;
    int arm = chest;
    if (!n.clavicle.empty()) arm = add(sided(n.clavicle, side), chest, Vec3(x * 0.05, 0.08, 0));
    arm = add(sided(n.upper_arm, side), arm, Vec3(x * 0.12, 0, 0));
    arm = add(sided(n.forearm, side), arm, Vec3(x * 0.28, 0, 0));
    const int hand = add(sided(n.hand, side), arm, Vec3(x * 0.25, 0, 0));
    if (!n.hand_child.empty()) {
      add("", add(sided(n.hand_child, side), hand, Vec3(x * 0.08, 0, 0)), Vec3(x * 0.05, 0, 0),
          true);
    } else if (n.fingers.empty()) {
      add("", hand, Vec3(x * 0.08, 0, 0), true);
    }
    for (const std::string& finger : n.fingers) {
      const int f = add(sided(finger, side), hand, Vec3(x * 0.04, 0, 0.02));
      add("", add(sided(finger, side) + "2", f, Vec3(x * 0.03, 0, 0)), Vec3(x * 0.02, 0, 0), true);
    }
    int leg = add(sided(n.thigh, side), hips, Vec3(x * 0.09, -0.05, 0));
    leg = add(sided(n.shin, side), leg, Vec3(0, -0.42, 0));
    leg = add(sided(n.foot, side), leg, Vec3(0, -0.42, 0));
    if (!n.toe.empty()) leg = add(sided(n.toe, side), leg, Vec3(0, -0.06, 0.12));
    add("", leg, Vec3(0, 0, 0.05), true);
  }
  EXPECT_EQ(s.validate(), "");
  return s;
}

// Checks every role against the expected joint name (without the rig's prefix).
void expect_roles(const Skeleton& s, const std::map<Role, std::string>& expected,
                  const std::string& prefix, const std::string& convention = "names") {
  JointRoles roles;
  std::string error;
  ASSERT_TRUE(detect_roles(s, roles, error)) << error;
  EXPECT_EQ(roles.convention, convention);
  for (const auto& [role, name] : expected) {
    const int j = roles[role];
    ASSERT_GE(j, 0) << role_name(role);
    EXPECT_EQ(s.joints[static_cast<std::size_t>(j)].name, prefix + name) << role_name(role);
  }
}

TEST(RoleDetection, MixamoNamesShoulderIsTheClavicle) {
  const RigNames n{"mixamorig:", "Hips", {"Spine", "Spine1", "Spine2"}, {"Neck"}, "Head",
                   "{}Shoulder", "{}Arm", "{}ForeArm", "{}Hand", "",
                   "{}UpLeg", "{}Leg", "{}Foot", "{}ToeBase", "Left", "Right",
                   {"{}HandThumb1", "{}HandIndex1"}};
  expect_roles(build(n),
               {{Role::kHips, "Hips"}, {Role::kSpine, "Spine1"}, {Role::kChest, "Spine2"},
                {Role::kNeck, "Neck"}, {Role::kHead, "Head"},
                {Role::kLeftShoulder, "LeftArm"}, {Role::kLeftElbow, "LeftForeArm"},
                {Role::kLeftWrist, "LeftHand"}, {Role::kRightShoulder, "RightArm"},
                {Role::kLeftHip, "LeftUpLeg"}, {Role::kLeftKnee, "LeftLeg"},
                {Role::kLeftAnkle, "LeftFoot"}, {Role::kLeftToe, "LeftToeBase"},
                {Role::kRightToe, "RightToeBase"}},
               "mixamorig:");
  RigNames underscore = n;
  underscore.prefix = "mixamorig_";
  expect_roles(build(underscore), {{Role::kRightElbow, "RightForeArm"}}, "mixamorig_");
}

TEST(RoleDetection, UnityHumanBodyBonesLeftShoulderIsNotTheUpperArm) {
  const RigNames n{"", "Hips", {"Spine", "Chest", "UpperChest"}, {"Neck"}, "Head",
                   "{}Shoulder", "{}UpperArm", "{}LowerArm", "{}Hand", "",
                   "{}UpperLeg", "{}LowerLeg", "{}Foot", "{}Toes", "Left", "Right", {}};
  expect_roles(build(n),
               {{Role::kChest, "UpperChest"}, {Role::kSpine, "Chest"},
                {Role::kLeftShoulder, "LeftUpperArm"}, {Role::kRightShoulder, "RightUpperArm"},
                {Role::kLeftElbow, "LeftLowerArm"}, {Role::kRightWrist, "RightHand"},
                {Role::kLeftHip, "LeftUpperLeg"}, {Role::kRightKnee, "RightLowerLeg"},
                {Role::kLeftToe, "LeftToes"}},
               "");
}

TEST(RoleDetection, PerceptionNeuronNamesWithFingersAndNoToes) {
  const RigNames n{"", "Hips", {"Spine", "Spine1", "Spine2", "Spine3"}, {"Neck"}, "Head",
                   "{}Shoulder", "{}Arm", "{}ForeArm", "{}Hand", "",
                   "{}UpLeg", "{}Leg", "{}Foot", "", "Left", "Right",
                   {"{}HandThumb1", "{}InHandIndex", "{}HandMiddle1"}};
  expect_roles(build(n),
               {{Role::kChest, "Spine3"}, {Role::kSpine, "Spine2"},
                {Role::kRightShoulder, "RightArm"}, {Role::kRightElbow, "RightForeArm"},
                {Role::kRightWrist, "RightHand"}, {Role::kRightAnkle, "RightFoot"},
                {Role::kRightToe, "RightFoot_End"}, {Role::kLeftToe, "LeftFoot_End"}},
               "");
}

TEST(RoleDetection, SmplShoulderIsTheUpperArmAndFootIsTheToe) {
  const RigNames n{"", "pelvis", {"spine1", "spine2", "spine3"}, {"neck"}, "head",
                   "{}_collar", "{}_shoulder", "{}_elbow", "{}_wrist", "{}_hand",
                   "{}_hip", "{}_knee", "{}_ankle", "{}_foot", "left", "right", {}};
  expect_roles(build(n),
               {{Role::kHips, "pelvis"}, {Role::kChest, "spine3"}, {Role::kSpine, "spine2"},
                {Role::kLeftShoulder, "left_shoulder"}, {Role::kLeftElbow, "left_elbow"},
                {Role::kLeftWrist, "left_wrist"}, {Role::kRightShoulder, "right_shoulder"},
                {Role::kLeftHip, "left_hip"}, {Role::kLeftKnee, "left_knee"},
                {Role::kLeftAnkle, "left_ankle"}, {Role::kLeftToe, "left_foot"},
                {Role::kRightToe, "right_foot"}},
               "");
}

TEST(RoleDetection, RigifyDotSidesAndUnnamedNeckAndHead) {
  // Rigify names the neck and head spine.004 ... spine.006: they are found as the branch above
  // the chest that holds no arm.
  const RigNames n{"DEF-", "spine", {"spine.001", "spine.002", "spine.003"},
                   {"spine.004", "spine.005"}, "spine.006",
                   "shoulder.{}", "upper_arm.{}", "forearm.{}", "hand.{}", "",
                   "thigh.{}", "shin.{}", "foot.{}", "toe.{}", "L", "R", {}};
  expect_roles(build(n),
               {{Role::kHips, "spine"}, {Role::kChest, "spine.003"}, {Role::kNeck, "spine.004"},
                {Role::kHead, "spine.006"}, {Role::kLeftShoulder, "upper_arm.L"},
                {Role::kRightElbow, "forearm.R"}, {Role::kLeftWrist, "hand.L"},
                {Role::kLeftHip, "thigh.L"}, {Role::kRightKnee, "shin.R"},
                {Role::kRightAnkle, "foot.R"}, {Role::kLeftToe, "toe.L"}},
               "DEF-");
}

TEST(RoleDetection, SidePrefixesAndBipedNames) {
  // l/r before a capital (DAZ-like), "Bip01 L ..." (3ds Max Biped), "_l" suffixes (Unreal).
  const RigNames daz{"", "hip", {"abdomen", "chest"}, {"neck"}, "head",
                     "{}Collar", "{}Shldr", "{}ForeArm", "{}Hand", "",
                     "{}Thigh", "{}Shin", "{}Foot", "", "l", "r", {"{}Index1", "{}Thumb1"}};
  RigNames renamed = daz;
  renamed.hips = "Hips";  // not the exact daz map any more
  expect_roles(build(renamed),
               {{Role::kLeftShoulder, "lShldr"}, {Role::kRightWrist, "rHand"},
                {Role::kLeftToe, "lFoot_End"}, {Role::kSpine, "abdomen"}},
               "");
  const RigNames biped{"Bip01 ", "Pelvis", {"Spine", "Spine1"}, {"Neck"}, "Head",
                       "{} Clavicle", "{} UpperArm", "{} Forearm", "{} Hand", "",
                       "{} Thigh", "{} Calf", "{} Foot", "{} Toe0", "L", "R", {}};
  expect_roles(build(biped),
               {{Role::kLeftShoulder, "L UpperArm"}, {Role::kRightKnee, "R Calf"},
                {Role::kLeftToe, "L Toe0"}},
               "Bip01 ");
  const RigNames unreal{"", "pelvis", {"spine_01", "spine_02", "spine_03"}, {"neck_01"}, "head",
                        "clavicle_{}", "upperarm_{}", "lowerarm_{}", "hand_{}", "",
                        "thigh_{}", "calf_{}", "foot_{}", "ball_{}", "l", "r", {}};
  expect_roles(build(unreal),
               {{Role::kLeftShoulder, "upperarm_l"}, {Role::kRightHip, "thigh_r"},
                {Role::kLeftToe, "ball_l"}, {Role::kNeck, "neck_01"}},
               "");
}

// Every joint renamed j0, j1, ...: the roles must come out as the same joints. `turn` turns the
// rest pose (every offset), as a rig exported Z-up stands along +Z.
void expect_same_roles_anonymised(const std::string& file, const std::string& convention,
                                  const Quat& turn = Quat::Identity()) {
  Result<Clip> clip = read_bvh(file);
  ASSERT_TRUE(clip) << clip.error().message;
  Skeleton s = clip.value().skeleton();
  JointRoles named;
  std::string error;
  ASSERT_TRUE(detect_roles(s, named, error)) << error;
  ASSERT_EQ(named.convention, convention);
  for (int j = 0; j < s.joint_count(); ++j) {
    s.joints[static_cast<std::size_t>(j)].name = "j" + std::to_string(j);
    s.joints[static_cast<std::size_t>(j)].offset =
        turn * s.joints[static_cast<std::size_t>(j)].offset;
  }
  JointRoles anonymous;
  ASSERT_TRUE(detect_roles(s, anonymous, error)) << error;
  EXPECT_EQ(anonymous.convention, "hierarchy");
  for (int r = 0; r < kRoleCount; ++r) {
    EXPECT_EQ(anonymous.joints[static_cast<std::size_t>(r)],
              named.joints[static_cast<std::size_t>(r)])
        << file << ": " << role_name(static_cast<Role>(r));
  }
}

TEST(RoleDetection, AnonymisedSalsaSkeletonFromTheHierarchy) {
  expect_same_roles_anonymised(std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/60/60_01_scaled.bvh",
                               "daz");
}

TEST(RoleDetection, AnonymisedHandshakeSkeletonFromTheHierarchy) {
  expect_same_roles_anonymised(std::string(DUET_DATA_DIR) + "/cmu-handshake/18_01.bvh",
                               "cmu-bvh");
}

TEST(RoleDetection, AnonymisedRigsStandingAlongZOrXFromTheHierarchy) {
  // A Z-up export's rest pose stands along +Z: its up is the spine's direction, not +Y (before,
  // the salsa rig turned Z-up had its left and right swapped and was followed 100 % lost).
  for (const UpAxis up : {UpAxis::kPosZ, UpAxis::kNegZ, UpAxis::kPosX}) {
    SCOPED_TRACE(std::string(up_axis_name(up)));
    const Quat turn = rotation_to_y_up(up).conjugate();
    expect_same_roles_anonymised(std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/60/60_01_scaled.bvh",
                                 "daz", turn);
    expect_same_roles_anonymised(std::string(DUET_DATA_DIR) + "/cmu-handshake/18_01.bvh", "cmu-bvh",
                                 turn);
  }
}

TEST(RoleDetection, MirroredAnonymousRigSwapsSides) {
  // The same anonymous rig facing -Z: left is now -X, so the +X limbs are the right ones.
  const RigNames n{"", "a", {"b", "c"}, {"d"}, "e", "", "f{}", "g{}", "h{}", "",
                   "i{}", "k{}", "m{}", "n{}", "1", "2", {}};
  Skeleton s = build(n);
  for (Joint& j : s.joints) j.offset.z() = -j.offset.z();
  JointRoles roles;
  std::string error;
  ASSERT_TRUE(detect_roles(s, roles, error)) << error;
  EXPECT_EQ(roles.convention, "hierarchy");
  EXPECT_EQ(s.joints[static_cast<std::size_t>(roles[Role::kLeftWrist])].name, "h2");
  EXPECT_EQ(s.joints[static_cast<std::size_t>(roles[Role::kRightHip])].name, "i1");
  EXPECT_EQ(s.joints[static_cast<std::size_t>(roles[Role::kRightToe])].name, "n1");
}

TEST(RoleDetection, NoLegsIsAClearError) {
  RigNames n{"", "Hips", {"Spine", "Chest"}, {"Neck"}, "Head", "{}Shoulder", "{}UpperArm",
             "{}LowerArm", "{}Hand", "", "", "", "", "", "Left", "Right", {}};
  // Build with legs, then drop them: keep only joints not below a thigh.
  n.thigh = "{}UpperLeg";
  n.shin = "{}LowerLeg";
  n.foot = "{}Foot";
  const Skeleton full = build(n);
  Skeleton s;
  std::vector<int> index(static_cast<std::size_t>(full.joint_count()), -1);
  for (int j = 0; j < full.joint_count(); ++j) {
    const Joint& joint = full.joints[static_cast<std::size_t>(j)];
    const bool leg = joint.name.find("Leg") != std::string::npos ||
                     joint.name.find("Foot") != std::string::npos;
    if (leg) continue;
    Joint copy = joint;
    copy.parent = joint.parent < 0 ? -1 : index[static_cast<std::size_t>(joint.parent)];
    index[static_cast<std::size_t>(j)] = s.joint_count();
    s.joints.push_back(copy);
  }
  ASSERT_EQ(s.validate(), "");
  JointRoles roles;
  std::string error;
  EXPECT_FALSE(detect_roles(s, roles, error));
  EXPECT_NE(error.find("left_ankle"), std::string::npos) << error;
  EXPECT_NE(error.find("no legs"), std::string::npos) << error;
  EXPECT_NE(error.find("--map"), std::string::npos) << error;
  const RoleDetection report = detect_roles_report(s);
  EXPECT_FALSE(report.complete());
  EXPECT_EQ(report.missing_roles().size(), 10u);  // four leg roles a side, hips, spine
  EXPECT_GE(report.roles[Role::kLeftWrist], 0);   // what was found is kept for duet inspect
}

TEST(RoleDetection, BuiltInConventionsStillWinWithTheirNotes) {
  Result<Clip> clip = read_bvh(std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/61/61_01_scaled.bvh");
  ASSERT_TRUE(clip) << clip.error().message;
  const RoleDetection report = detect_roles_report(clip.value().skeleton());
  ASSERT_TRUE(report.complete()) << report.problem;
  EXPECT_EQ(report.roles.convention, "daz");
  EXPECT_EQ(report.notes[static_cast<std::size_t>(Role::kLeftShoulder)],
            "built-in map daz: 'lShldr'");
}

}  // namespace
}  // namespace duet
