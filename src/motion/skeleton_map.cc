#include "duet/motion/skeleton_map.h"

#include <fstream>
#include <nlohmann/json.hpp>

#include "duet/motion/role_detection.h"

namespace duet {

namespace {

constexpr std::array<std::string_view, kRoleCount> kRoleNames = {
    "hips",       "spine",         "chest",       "neck",         "head",
    "left_shoulder", "left_elbow", "left_wrist",  "right_shoulder", "right_elbow",
    "right_wrist", "left_hip",     "left_knee",   "left_ankle",   "left_toe",
    "right_hip",  "right_knee",    "right_ankle", "right_toe"};

SkeletonMap make_map(std::string name, std::array<std::string, kRoleCount> joint_names) {
  return SkeletonMap{std::move(name), std::move(joint_names)};
}

}  // namespace

std::string_view role_name(Role role) { return kRoleNames[static_cast<std::size_t>(role)]; }

bool parse_role(std::string_view name, Role& role) {
  for (std::size_t k = 0; k < kRoleNames.size(); ++k) {
    if (kRoleNames[k] == name) {
      role = static_cast<Role>(k);
      return true;
    }
  }
  return false;
}

const std::vector<SkeletonMap>& builtin_skeleton_maps() {
  // Order of roles as in the Role enum. End Sites are named "<parent>_End" by the BVH reader.
  static const std::vector<SkeletonMap> maps = {
      make_map("daz", {"hip", "abdomen", "chest", "neck", "head", "lShldr", "lForeArm", "lHand",
                       "rShldr", "rForeArm", "rHand", "lThigh", "lShin", "lFoot", "lFoot_End",
                       "rThigh", "rShin", "rFoot", "rFoot_End"}),
      make_map("cmu-bvh", {"Hips", "Spine", "Spine1", "Neck", "Head", "LeftArm", "LeftForeArm",
                           "LeftHand", "RightArm", "RightForeArm", "RightHand", "LeftUpLeg",
                           "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg",
                           "RightFoot", "RightToeBase"}),
      make_map("cmu-asf", {"root", "upperback", "thorax", "lowerneck", "head", "lhumerus",
                           "lradius", "lwrist", "rhumerus", "rradius", "rwrist", "lfemur",
                           "ltibia", "lfoot", "ltoes", "rfemur", "rtibia", "rfoot", "rtoes"}),
  };
  return maps;
}

bool resolve_roles(const Skeleton& skeleton, const SkeletonMap& map, JointRoles& roles,
                   std::string& missing) {
  missing.clear();
  roles.convention = map.name;
  for (int r = 0; r < kRoleCount; ++r) {
    const std::string& joint = map.joint_names[static_cast<std::size_t>(r)];
    const int index = skeleton.find(joint);
    roles.joints[static_cast<std::size_t>(r)] = index;
    if (index < 0) {
      if (!missing.empty()) missing += ", ";
      missing += std::string(role_name(static_cast<Role>(r))) + " ('" + joint + "')";
    }
  }
  return missing.empty();
}

bool detect_roles(const Skeleton& skeleton, JointRoles& roles, std::string& error) {
  RoleDetection detection = detect_roles_report(skeleton);
  roles = detection.roles;
  if (detection.complete()) return true;
  error = std::move(detection.problem);
  return false;
}

bool load_skeleton_map(const std::string& path, SkeletonMap& map, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = path + ": cannot open skeleton map";
    return false;
  }
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    error = path + ": not valid JSON: " + e.what();
    return false;
  }
  if (!doc.is_object() || !doc.contains("roles") || !doc["roles"].is_object()) {
    error = path + ": expected an object with a \"roles\" object";
    return false;
  }
  map = SkeletonMap{};
  map.name = doc.value("name", path);
  std::string missing;
  for (auto it = doc["roles"].begin(); it != doc["roles"].end(); ++it) {
    Role role{};
    if (!parse_role(it.key(), role)) {
      error = path + ": unknown role \"" + it.key() + "\"";
      return false;
    }
    if (!it.value().is_string()) {
      error = path + ": role \"" + it.key() + "\" must name a joint (a string)";
      return false;
    }
    map.joint_names[static_cast<std::size_t>(role)] = it.value().get<std::string>();
  }
  for (int r = 0; r < kRoleCount; ++r) {
    if (map.joint_names[static_cast<std::size_t>(r)].empty()) {
      if (!missing.empty()) missing += ", ";
      missing += role_name(static_cast<Role>(r));
    }
  }
  if (!missing.empty()) {
    error = path + ": roles not given: " + missing;
    return false;
  }
  return true;
}

}  // namespace duet
