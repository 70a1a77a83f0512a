// Joint roles: features and corrections name body parts by role, not by joint name. A skeleton
// map says which joint plays each role; maps for the conventions in the CMU data ship built in,
// and a user can load their own from JSON.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "duet/motion/skeleton.h"

namespace duet {

enum class Role : int {
  kHips,
  kSpine,
  kChest,
  kNeck,
  kHead,
  kLeftShoulder,  // upper-arm joint (rotates the upper arm)
  kLeftElbow,     // forearm joint
  kLeftWrist,     // hand joint
  kRightShoulder,
  kRightElbow,
  kRightWrist,
  kLeftHip,  // thigh joint
  kLeftKnee,
  kLeftAnkle,
  kLeftToe,
  kRightHip,
  kRightKnee,
  kRightAnkle,
  kRightToe,
  kCount
};
constexpr int kRoleCount = static_cast<int>(Role::kCount);

std::string_view role_name(Role role);  // "hips", "left_wrist", ...
bool parse_role(std::string_view name, Role& role);

// A named convention: for each role, the joint name.
struct SkeletonMap {
  std::string name;
  std::array<std::string, kRoleCount> joint_names;
};

// The joint index of every role in one skeleton.
struct JointRoles {
  // How the roles were found: a built-in map's name ("daz", ...), a user map's name, "names"
  // (from the joint names) or "hierarchy" (from the tree and the rest pose); see role_detection.h.
  std::string convention;
  std::array<int, kRoleCount> joints{};
  int operator[](Role role) const { return joints[static_cast<int>(role)]; }
};

// The built-in maps: "daz" (the CMU salsa BVH), "cmu-bvh" (MotionBuilder-style CMU BVH),
// "cmu-asf" (CMU ASF skeletons and their BVH conversions).
const std::vector<SkeletonMap>& builtin_skeleton_maps();

// Resolves `map` against `skeleton`. On failure returns false and puts the missing roles (with
// the joint names looked for) into `missing`.
bool resolve_roles(const Skeleton& skeleton, const SkeletonMap& map, JointRoles& roles,
                   std::string& missing);

// Tries every built-in map, then the joint names, then the hierarchy (detect_roles_report in
// role_detection.h). On failure, `error` says which roles each way lacked.
bool detect_roles(const Skeleton& skeleton, JointRoles& roles, std::string& error);

// Loads a map from a JSON file: {"name": "...", "roles": {"hips": "Hips", ...}}. Every role must
// be given. Returns false with a "file: reason" message in `error`.
bool load_skeleton_map(const std::string& path, SkeletonMap& map, std::string& error);

}  // namespace duet
