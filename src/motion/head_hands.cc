#include "duet/motion/head_hands.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "duet/math/median.h"
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

namespace {

// The rest pose's joint positions (every rotation the identity), stood on +Y when the rig has
// feet and a head: a rig exported Z-up stands along +Z in its rest pose, so its up is found
// (feet to head, to the nearest axis) and turned to +Y. `to_y_up` is that turn.
std::vector<Vec3> upright_rest_positions(const Skeleton& skeleton, const JointRoles& roles,
                                         Quat& to_y_up) {
  const auto n = static_cast<std::size_t>(skeleton.joint_count());
  std::vector<Vec3> translations(n), positions(n);
  std::vector<Quat> rotations(n, Quat::Identity()), world_rotations(n);
  for (std::size_t j = 0; j < n; ++j) translations[j] = skeleton.joints[j].offset;
  forward_kinematics(skeleton, translations, rotations, positions, world_rotations);
  to_y_up = Quat::Identity();
  if (has_feet_and_head(roles, skeleton.joint_count())) {
    to_y_up = rotation_to_y_up(nearest_axis(feet_to_head(positions, roles)));
    for (Vec3& p : positions) p = to_y_up * p;
  }
  return positions;
}

// The mean of unit quaternions, each first put in the hemisphere of the first (q and -q are one
// rotation). Good for rotations that spread over well under a half turn.
Quat mean_rotation(const std::vector<Quat>& rotations) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (const Quat& q : rotations) {
    const Eigen::Vector4d v = q.coeffs();
    sum += v.dot(rotations.front().coeffs()) < 0.0 ? Eigen::Vector4d(-v) : v;
  }
  Quat mean;
  mean.coeffs() = sum.normalized();
  return mean;
}

}  // namespace

Result<Quat> rest_pose_correction(const Skeleton& skeleton, const JointRoles& roles) {
  if (is_head_hands_input(roles)) return head_hands_device_correction();
  Quat to_y_up;
  const std::vector<Vec3> positions = upright_rest_positions(skeleton, roles, to_y_up);
  const double yaw = body_heading_yaw(positions, roles);
  if (!std::isfinite(yaw)) {
    return Error{"the rest pose has no heading (no hip joints, or both at one place)"};
  }
  return to_y_up.conjugate() * yaw_rotation(yaw);
}

bool rest_pose_stands(const Skeleton& skeleton, const JointRoles& roles) {
  if (!has_feet_and_head(roles, skeleton.joint_count())) return true;  // nothing to tell by
  for (Role role : {Role::kLeftHip, Role::kRightHip}) {
    if (roles[role] < 0 || roles[role] >= skeleton.joint_count()) return true;
  }
  Quat to_y_up;
  const std::vector<Vec3> positions = upright_rest_positions(skeleton, roles, to_y_up);
  auto height_of = [&](Role role) { return positions[static_cast<std::size_t>(roles[role])].y(); };
  const double pelvis = pelvis_centre(positions, roles).y();
  const double lowest = std::min(height_of(Role::kLeftAnkle), height_of(Role::kRightAnkle));
  const double height = height_of(Role::kHead) - lowest;
  if (!(height > 0.0)) return false;
  // A standing body's ankles are about half its height below the pelvis (0.45-0.5 in the salsa,
  // ASF and handshake rigs' rest poses), its head about 0.4 above it.
  return height_of(Role::kLeftAnkle) < pelvis - 0.3 * height &&
         height_of(Role::kRightAnkle) < pelvis - 0.3 * height &&
         height_of(Role::kHead) > pelvis + 0.2 * height;
}

Result<Quat> head_correction(const Clip& full_body, const JointRoles& roles) {
  if (rest_pose_stands(full_body.skeleton(), roles)) {
    return rest_pose_correction(full_body.skeleton(), roles);
  }
  const int head = roles[Role::kHead];
  if (head < 0 || head >= full_body.joint_count()) return Error{"no joint for role head"};
  const auto n = static_cast<std::size_t>(full_body.joint_count());
  std::vector<Vec3> positions(n);
  std::vector<Quat> world(n);
  std::vector<Quat> per_frame;
  per_frame.reserve(static_cast<std::size_t>(full_body.frame_count()));
  for (int f = 0; f < full_body.frame_count(); ++f) {
    forward_kinematics(full_body.skeleton(), full_body.translations_ls(f),
                       full_body.rotations_ls(f), positions, world);
    const double yaw = body_heading_yaw(positions, roles);
    // R_head * correction = the pelvis's heading frame, frame by frame.
    if (std::isfinite(yaw)) {
      per_frame.push_back(world[static_cast<std::size_t>(head)].conjugate() * yaw_rotation(yaw));
    }
  }
  if (per_frame.empty()) {
    return Error{
        "the rest pose does not stand and no frame has a heading (hip joints at one place?), so "
        "where the head faces is unknown"};
  }
  return mean_rotation(per_frame);
}

Result<std::array<Quat, 2>> rest_grip_frames(const Skeleton& skeleton, const JointRoles& roles) {
  const auto in_rig = [&](Role role) {
    return roles[role] >= 0 && roles[role] < skeleton.joint_count();
  };
  // Each wrist's bone toward its arm: its offset, or its parents' where it sits on them.
  constexpr Role kWrists[] = {Role::kLeftWrist, Role::kRightWrist};
  std::array<Vec3, 2> to_arm;
  for (std::size_t hand = 0; hand < 2; ++hand) {
    Vec3 bone = Vec3::Zero();
    if (in_rig(kWrists[hand])) {
      for (int j = roles[kWrists[hand]]; j >= 0 && bone.norm() < 1e-6;
           j = skeleton.joints[static_cast<std::size_t>(j)].parent) {
        bone = skeleton.joints[static_cast<std::size_t>(j)].offset;
      }
    }
    if (bone.norm() < 1e-6) {
      return Error{"the " + std::string(role_name(kWrists[hand])) +
                   " joint has no bone to its arm"};
    }
    to_arm[hand] = -bone.normalized();
  }
  Quat to_y_up;
  const std::vector<Vec3> positions = upright_rest_positions(skeleton, roles, to_y_up);
  const double yaw = body_heading_yaw(positions, roles);  // NaN without hips: face +Z
  const Vec3 forward =
      to_y_up.conjugate() * (yaw_rotation(std::isfinite(yaw) ? yaw : 0.0) * Vec3::UnitZ());
  const Vec3 down = to_y_up.conjugate() * -Vec3::UnitY();
  std::array<Quat, 2> grips;
  for (std::size_t hand = 0; hand < 2; ++hand) {
    const Vec3& arm = to_arm[hand];
    auto square_to_arm = [&](const Vec3& v) { return Vec3(v - v.dot(arm) * arm); };
    Vec3 palm = square_to_arm(down);
    if (palm.norm() < 0.5) palm = square_to_arm(-forward);
    palm.normalize();
    const Vec3 x = kWrists[hand] == Role::kRightWrist ? Vec3(-palm) : palm;
    Eigen::Matrix3d axes;
    axes.col(0) = x;
    axes.col(1) = arm;
    axes.col(2) = x.cross(arm);
    grips[hand] = Quat(axes).normalized();
  }
  return grips;
}

Result<Clip> head_hands_clip(const Clip& full_body, const JointRoles& roles,
                             const DevicePointOffsets& offsets) {
  for (Role role : {Role::kHead, Role::kLeftWrist, Role::kRightWrist}) {
    const int joint = roles[role];
    if (joint < 0 || joint >= full_body.joint_count()) {
      return Error{"no joint for role " + std::string(role_name(role)) +
                   " (three points need a head and two wrists)"};
    }
  }
  Result<Quat> correction = head_correction(full_body, roles);
  if (!correction) return correction.error();
  Result<std::array<Quat, 2>> grips = rest_grip_frames(full_body.skeleton(), roles);
  if (!grips) return grips.error();
  // Each point's device rotation from its joint's world rotation: the head's so that
  // R_device * device_correction = R_world * head correction (the same canonical frame), the
  // hands' their grip frames.
  const Quat to_device[] = {correction.value() * head_hands_device_correction().conjugate(),
                            grips.value()[0], grips.value()[1]};
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
      const Quat device = (rotations[source] * to_device[p]).normalized();
      // Where the device sits: device_points_to_joints' inverse.
      const Vec3 offset = p == 0 ? Vec3(rotations[source] * correction.value() * offsets.eyes_m)
                                 : Vec3(-offsets.grip_m * (device * Vec3::UnitY()));
      points.translations_ls(f)[static_cast<std::size_t>(p + 1)] = positions[source] + offset;
      points.rotations_ls(f)[static_cast<std::size_t>(p + 1)] = device;
    }
  }
  return points;
}

double highest_head_m(const Clip& clip, const JointRoles& roles, int frames) {
  const int head = roles[Role::kHead];
  if (head < 0 || head >= clip.joint_count()) return 0.0;
  const auto n = static_cast<std::size_t>(clip.joint_count());
  std::vector<Vec3> positions(n);
  std::vector<Quat> rotations(n);
  const int count = std::min(frames, clip.frame_count());
  std::vector<double> heights;
  heights.reserve(static_cast<std::size_t>(std::max(count, 0)));
  for (int f = 0; f < count; ++f) {
    forward_kinematics(clip.skeleton(), clip.translations_ls(f), clip.rotations_ls(f), positions,
                       rotations);
    heights.push_back(positions[static_cast<std::size_t>(head)].y());
  }
  if (heights.empty()) return 0.0;
  // The level the head holds: the median of each half second, so that a hop, a stretch on tiptoe
  // for a moment or a sensor's spike does not pass for the body's height.
  constexpr double kHeldS = 0.5;
  const auto window = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::lround(kHeldS * clip.frame_rate())), 1, heights.size());
  double highest = 0.0;
  std::vector<double> held;
  held.reserve(window);
  for (std::size_t start = 0; start + window <= heights.size(); ++start) {
    held.clear();
    for (std::size_t f = start; f < start + window; ++f) {
      if (std::isfinite(heights[f])) held.push_back(heights[f]);
    }
    if (!held.empty()) highest = std::max(highest, upper_median(held));
  }
  return highest;
}

}  // namespace duet
