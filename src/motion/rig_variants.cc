#include "duet/motion/rig_variants.h"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <vector>

#include "duet/base/parse_number.h"
#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"

namespace duet {

namespace {

// in[j]: joint j is `root` or below it (parents come before children).
std::vector<bool> subtree(const Skeleton& skeleton, int root) {
  std::vector<bool> in(skeleton.joints.size(), false);
  for (std::size_t j = 0; j < in.size(); ++j) {
    const int parent = skeleton.joints[j].parent;
    in[j] = static_cast<int>(j) == root || (parent >= 0 && in[static_cast<std::size_t>(parent)]);
  }
  return in;
}

// Turns the rest pose of everything below `root` by `rotation` about `root`.
void turn_subtree(Skeleton& skeleton, int root, const Quat& rotation) {
  const std::vector<bool> in = subtree(skeleton, root);
  for (std::size_t j = 0; j < in.size(); ++j) {
    if (in[j] && static_cast<int>(j) != root)
      skeleton.joints[j].offset = rotation * skeleton.joints[j].offset;
  }
}

// Turns the subtree of `joint` so that its bone towards `end` moves by `degrees` towards `toward`.
void turn_bone_toward(Skeleton& skeleton, int joint, int end, const Vec3& toward, double degrees) {
  if (degrees == 0.0) return;
  const std::vector<Vec3> rest = rest_positions(skeleton);
  const Vec3 bone = rest[static_cast<std::size_t>(end)] - rest[static_cast<std::size_t>(joint)];
  const Vec3 axis = bone.cross(toward);
  if (!(axis.norm() > 1e-9 * std::max(1.0, bone.norm()))) return;  // already along `toward`
  turn_subtree(skeleton, joint, quat_from_axis_angle(axis.normalized(), deg_to_rad(degrees)));
}

}  // namespace

Skeleton make_proportioned_rig(const Skeleton& skeleton, const JointRoles& roles,
                               const RigProportions& proportions) {
  Skeleton rig = skeleton;
  const auto n = rig.joints.size();
  const std::vector<bool> left_arm = subtree(rig, roles[Role::kLeftShoulder]);
  const std::vector<bool> right_arm = subtree(rig, roles[Role::kRightShoulder]);
  const std::vector<bool> left_leg = subtree(rig, roles[Role::kLeftHip]);
  const std::vector<bool> right_leg = subtree(rig, roles[Role::kRightHip]);
  // An offset belongs to the part its parent joint is in.
  for (std::size_t j = 0; j < n; ++j) {
    const int parent = rig.joints[j].parent;
    if (parent < 0) continue;
    const auto p = static_cast<std::size_t>(parent);
    const double factor = left_arm[p] || right_arm[p]   ? proportions.arms
                          : left_leg[p] || right_leg[p] ? proportions.legs
                                                        : proportions.trunk;
    rig.joints[j].offset *= factor;
  }

  // Body axes of the rest pose: left from the hip joints, up, forward = left x up.
  const std::vector<Vec3> rest = rest_positions(rig);
  Vec3 left = rest[static_cast<std::size_t>(roles[Role::kLeftHip])] -
              rest[static_cast<std::size_t>(roles[Role::kRightHip])];
  left.y() = 0.0;
  left = left.norm() > 1e-9 ? left.normalized() : Vec3::UnitX();
  const Vec3 up = Vec3::UnitY();
  const Vec3 forward = left.cross(up);

  turn_bone_toward(rig, roles[Role::kLeftShoulder], roles[Role::kLeftElbow], -up,
                   proportions.arms_down_deg);
  turn_bone_toward(rig, roles[Role::kRightShoulder], roles[Role::kRightElbow], -up,
                   proportions.arms_down_deg);
  turn_bone_toward(rig, roles[Role::kLeftHip], roles[Role::kLeftKnee], left,
                   proportions.legs_apart_deg);
  turn_bone_toward(rig, roles[Role::kRightHip], roles[Role::kRightKnee], -left,
                   proportions.legs_apart_deg);
  if (proportions.toes_out_deg != 0.0) {
    // About the vertical: the left foot turns to the left, the right to the right.
    turn_subtree(rig, roles[Role::kLeftAnkle],
                 quat_from_axis_angle(forward.cross(left).normalized(),
                                      deg_to_rad(proportions.toes_out_deg)));
    turn_subtree(rig, roles[Role::kRightAnkle],
                 quat_from_axis_angle(forward.cross(-left).normalized(),
                                      deg_to_rad(proportions.toes_out_deg)));
  }
  turn_bone_toward(rig, roles[Role::kSpine], roles[Role::kChest], forward,
                   proportions.trunk_lean_deg);
  return rig;
}

bool parse_rig_proportions(std::string_view text, RigProportions& proportions, std::string& error) {
  RigProportions parsed = proportions;
  while (!text.empty()) {
    const std::size_t comma = text.find(',');
    const std::string_view item = text.substr(0, comma);
    text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) {
      error = fmt::format("'{}': expected key=value", item);
      return false;
    }
    const std::string_view key = item.substr(0, eq), value_text = item.substr(eq + 1);
    const std::optional<double> number = parse_number<double>(value_text);
    if (!number) {
      error = fmt::format("'{}': the value is not a number", item);
      return false;
    }
    const double value = *number;
    const bool factor = key == "arms" || key == "legs" || key == "trunk";
    if (factor && !(value > 0.0 && value <= 10.0)) {
      error = fmt::format("'{}': a length factor must be in (0, 10]", item);
      return false;
    }
    if (!factor && !(std::abs(value) <= 90.0)) {
      error = fmt::format("'{}': an angle must be within [-90, 90] degrees", item);
      return false;
    }
    if (key == "arms")
      parsed.arms = value;
    else if (key == "legs")
      parsed.legs = value;
    else if (key == "trunk")
      parsed.trunk = value;
    else if (key == "arms_down")
      parsed.arms_down_deg = value;
    else if (key == "legs_apart")
      parsed.legs_apart_deg = value;
    else if (key == "lean")
      parsed.trunk_lean_deg = value;
    else if (key == "toes_out")
      parsed.toes_out_deg = value;
    else {
      error = fmt::format(
          "'{}': unknown key (arms, legs, trunk, arms_down, legs_apart, lean, toes_out)", key);
      return false;
    }
  }
  proportions = parsed;
  return true;
}

}  // namespace duet
