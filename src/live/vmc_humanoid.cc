#include "duet/live/vmc_humanoid.h"

#include <array>
#include <stdexcept>

namespace duet {

namespace {

struct BoneSpec {
  const char* name;
  const char* parent;  // nullptr: the root
  double x, y, z;      // offset from the parent, metres, Duet axes
};

// A 1.7 m adult in a T-pose (arms along +-X, facing +Z); lengths from typical VRM avatars.
constexpr std::array<BoneSpec, 22> kBones = {{
    {"Hips", nullptr, 0.0, 0.95, 0.0},
    {"Spine", "Hips", 0.0, 0.10, 0.0},
    {"Chest", "Spine", 0.0, 0.12, 0.0},
    {"UpperChest", "Chest", 0.0, 0.12, 0.0},
    {"Neck", "UpperChest", 0.0, 0.12, 0.0},
    {"Head", "Neck", 0.0, 0.10, 0.0},
    {"LeftShoulder", "UpperChest", 0.02, 0.08, 0.0},
    {"LeftUpperArm", "LeftShoulder", 0.13, 0.0, 0.0},
    {"LeftLowerArm", "LeftUpperArm", 0.28, 0.0, 0.0},
    {"LeftHand", "LeftLowerArm", 0.26, 0.0, 0.0},
    {"RightShoulder", "UpperChest", -0.02, 0.08, 0.0},
    {"RightUpperArm", "RightShoulder", -0.13, 0.0, 0.0},
    {"RightLowerArm", "RightUpperArm", -0.28, 0.0, 0.0},
    {"RightHand", "RightLowerArm", -0.26, 0.0, 0.0},
    {"LeftUpperLeg", "Hips", 0.09, -0.05, 0.0},
    {"LeftLowerLeg", "LeftUpperLeg", 0.0, -0.42, 0.0},
    {"LeftFoot", "LeftLowerLeg", 0.0, -0.40, 0.0},
    {"LeftToes", "LeftFoot", 0.0, -0.06, 0.12},
    {"RightUpperLeg", "Hips", -0.09, -0.05, 0.0},
    {"RightLowerLeg", "RightUpperLeg", 0.0, -0.42, 0.0},
    {"RightFoot", "RightLowerLeg", 0.0, -0.40, 0.0},
    {"RightToes", "RightFoot", 0.0, -0.06, 0.12},
}};

struct EndSpec {
  const char* parent;
  double x, y, z;
};
constexpr std::array<EndSpec, 5> kEnds = {{
    {"Head", 0.0, 0.18, 0.0},
    {"LeftHand", 0.10, 0.0, 0.0},
    {"RightHand", -0.10, 0.0, 0.0},
    {"LeftToes", 0.0, 0.0, 0.05},
    {"RightToes", 0.0, 0.0, 0.05},
}};

std::shared_ptr<const Skeleton> build_skeleton() {
  auto skeleton = std::make_shared<Skeleton>();
  for (const BoneSpec& b : kBones) {
    Joint joint;
    joint.name = b.name;
    joint.parent = b.parent == nullptr ? -1 : skeleton->find(b.parent);
    joint.offset = Vec3(b.x, b.y, b.z);
    if (joint.parent < 0) {
      joint.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition};
    }
    joint.channels.insert(joint.channels.end(),
                          {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation});
    skeleton->joints.push_back(std::move(joint));
  }
  for (const EndSpec& e : kEnds) {
    Joint joint;
    joint.name = std::string(e.parent) + "_End";
    joint.parent = skeleton->find(e.parent);
    joint.offset = Vec3(e.x, e.y, e.z);
    joint.end_site = true;
    skeleton->joints.push_back(std::move(joint));
  }
  return skeleton;
}

SkeletonMap vmc_map() {
  SkeletonMap map;
  map.name = "vmc";
  const std::array<const char*, kRoleCount> names = {
      "Hips",          "Spine",         "UpperChest",   "Neck",          "Head",
      "LeftUpperArm",  "LeftLowerArm",  "LeftHand",     "RightUpperArm", "RightLowerArm",
      "RightHand",     "LeftUpperLeg",  "LeftLowerLeg", "LeftFoot",      "LeftToes",
      "RightUpperLeg", "RightLowerLeg", "RightFoot",    "RightToes"};
  for (int r = 0; r < kRoleCount; ++r)
    map.joint_names[static_cast<std::size_t>(r)] = names[static_cast<std::size_t>(r)];
  return map;
}

}  // namespace

SourceSkeleton vmc_humanoid(double frame_rate) {
  static const std::shared_ptr<const Skeleton> skeleton = build_skeleton();
  static const JointRoles roles = [] {
    JointRoles r;
    std::string missing;
    if (!resolve_roles(*skeleton, vmc_map(), r, missing)) {
      throw std::logic_error("vmc humanoid: roles missing: " + missing);  // a bug in the tables
    }
    return r;
  }();
  SourceSkeleton s;
  s.skeleton = skeleton;
  s.roles = roles;
  s.metres_per_unit = 1.0;
  s.frame_rate = frame_rate;
  return s;
}

int vmc_bone_index(std::string_view name) noexcept {
  for (std::size_t k = 0; k < kBones.size(); ++k) {
    if (name == kBones[k].name) return static_cast<int>(k);
  }
  return -1;
}

Vec3 unity_to_duet(const Vec3& p) noexcept { return Vec3(-p.x(), p.y(), p.z()); }

Quat unity_to_duet(const Quat& q) noexcept { return Quat(q.w(), q.x(), -q.y(), -q.z()); }

}  // namespace duet
