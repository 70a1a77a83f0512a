#include "duet/motion/head_hands.h"

#include <cmath>

#include "duet/math/rotation.h"
#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/up_axis.h"

namespace duet {

std::shared_ptr<const Skeleton> make_head_hands_skeleton() {
  auto skeleton = std::make_shared<Skeleton>();
  const std::vector<Channel> channels = {Channel::kXposition, Channel::kYposition,
                                         Channel::kZposition, Channel::kZrotation,
                                         Channel::kXrotation, Channel::kYrotation};
  skeleton->joints.push_back(Joint{"origin", -1, Vec3::Zero(), {}, false});
  for (const char* name : {"head", "left_hand", "right_hand"}) {
    skeleton->joints.push_back(Joint{name, kPointsOrigin, Vec3::Zero(), channels, false});
  }
  return skeleton;
}

JointRoles head_hands_roles() {
  JointRoles roles;
  roles.convention = "head-hands";
  roles.joints.fill(-1);
  roles.joints[static_cast<int>(Role::kHead)] = kPointsHead;
  roles.joints[static_cast<int>(Role::kLeftWrist)] = kPointsLeftHand;
  roles.joints[static_cast<int>(Role::kRightWrist)] = kPointsRightHand;
  return roles;
}

bool is_head_hands_input(const JointRoles& roles) {
  return roles[Role::kHips] < 0 && roles[Role::kHead] >= 0 && roles[Role::kLeftWrist] >= 0 &&
         roles[Role::kRightWrist] >= 0;
}

Quat head_hands_device_correction() { return yaw_rotation(kPi); }

Result<Quat> rest_pose_correction(const Skeleton& skeleton, const JointRoles& roles) {
  if (is_head_hands_input(roles)) return head_hands_device_correction();
  const auto n = static_cast<std::size_t>(skeleton.joint_count());
  std::vector<Vec3> translations(n), positions(n);
  std::vector<Quat> rotations(n, Quat::Identity()), world_rotations(n);
  for (std::size_t j = 0; j < n; ++j) translations[j] = skeleton.joints[j].offset;
  forward_kinematics(skeleton, translations, rotations, positions, world_rotations);
  // A rig exported Z-up stands along +Z in its rest pose: find its up (feet to head, to the
  // nearest axis), stand it on +Y to read its heading, and turn the frame back.
  Quat to_y_up = Quat::Identity();
  if (has_feet_and_head(roles, skeleton.joint_count())) {
    to_y_up = rotation_to_y_up(nearest_axis(feet_to_head(positions, roles)));
    for (Vec3& p : positions) p = to_y_up * p;
  }
  const double yaw = body_heading_yaw(positions, roles);
  if (!std::isfinite(yaw)) {
    return Error{"the rest pose has no heading (hip joints at one place?)"};
  }
  return to_y_up.conjugate() * yaw_rotation(yaw);
}

Result<Clip> head_hands_clip(const Clip& full_body, const JointRoles& roles) {
  for (Role role : {Role::kHead, Role::kLeftWrist, Role::kRightWrist}) {
    const int joint = roles[role];
    if (joint < 0 || joint >= full_body.joint_count()) {
      return Error{"no joint for role " + std::string(role_name(role)) +
                   " (three points need a head and two wrists)"};
    }
  }
  Result<Quat> correction = rest_pose_correction(full_body.skeleton(), roles);
  if (!correction) return correction.error();
  // R_device * device_correction = R_world * rest correction: the same canonical frame.
  const Quat to_device = correction.value() * head_hands_device_correction().conjugate();
  Clip points(make_head_hands_skeleton(), full_body.frame_rate(), full_body.frame_count());
  const auto n = static_cast<std::size_t>(full_body.joint_count());
  std::vector<Vec3> positions(n);
  std::vector<Quat> rotations(n);
  const int sources[] = {roles[Role::kHead], roles[Role::kLeftWrist], roles[Role::kRightWrist]};
  for (int f = 0; f < full_body.frame_count(); ++f) {
    forward_kinematics(full_body.skeleton(), full_body.translations_ls(f),
                       full_body.rotations_ls(f), positions, rotations);
    for (int p = 0; p < 3; ++p) {
      const auto source = static_cast<std::size_t>(sources[p]);
      points.translations_ls(f)[static_cast<std::size_t>(p + 1)] = positions[source];
      points.rotations_ls(f)[static_cast<std::size_t>(p + 1)] =
          (rotations[source] * to_device).normalized();
    }
  }
  return points;
}

}  // namespace duet
