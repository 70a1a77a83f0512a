#include "duet/motion/body_space.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "duet/motion/forward_kinematics.h"

namespace duet {

namespace {

// Length along the bones from `ancestor` down to `joint` (the sum of the rest offsets of every
// joint on the way). When `ancestor` is not above `joint` (a map that names odd joints), the
// straight distance between the two in the rest pose.
double chain_length(const Skeleton& skeleton, int ancestor, int joint,
                    const std::vector<Vec3>& rest_positions) {
  if (ancestor < 0 || joint < 0) return 0.0;
  double length = 0.0;
  for (int j = joint; j >= 0; j = skeleton.joints[static_cast<std::size_t>(j)].parent) {
    if (j == ancestor) return length;
    length += skeleton.joints[static_cast<std::size_t>(j)].offset.norm();
  }
  return (rest_positions[static_cast<std::size_t>(joint)] -
          rest_positions[static_cast<std::size_t>(ancestor)])
      .norm();
}

// The share of standing height that lies outside "ankle to head joint": the ankle's height above
// the floor and the skull above the head joint. Calibrated on the CMU subjects 60, 61, 18 and 19
// (docs/rigs.md), adults of about 1.6-1.9 m: 1.17 gives 1.75 m (salsa 60/61 BVH), 1.71 m
// (60.asf), 1.62 and 1.68 m (handshake 18, 19); 1.12 put subject 18 at 1.55 m.
constexpr double kHeightPerChainLength = 1.17;

}  // namespace

BodyDimensions measure_body(const Skeleton& skeleton, const JointRoles& roles,
                            double metres_per_unit) {
  BodyDimensions body;
  const int n = skeleton.joint_count();
  if (n == 0) return body;
  std::vector<Vec3> translations(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) translations[static_cast<std::size_t>(j)] = skeleton.joints[static_cast<std::size_t>(j)].offset;
  std::vector<Quat> rotations(static_cast<std::size_t>(n), Quat::Identity());
  std::vector<Vec3> positions(static_cast<std::size_t>(n));
  std::vector<Quat> world_rotations(static_cast<std::size_t>(n));
  forward_kinematics(skeleton, translations, rotations, positions, world_rotations);

  auto chain = [&](Role from, Role to) {
    return metres_per_unit * chain_length(skeleton, roles[from], roles[to], positions);
  };
  body.leg_length_m = 0.5 * (chain(Role::kLeftHip, Role::kLeftKnee) +
                             chain(Role::kLeftKnee, Role::kLeftAnkle) +
                             chain(Role::kRightHip, Role::kRightKnee) +
                             chain(Role::kRightKnee, Role::kRightAnkle));
  body.arm_length_m = 0.5 * (chain(Role::kLeftShoulder, Role::kLeftElbow) +
                             chain(Role::kLeftElbow, Role::kLeftWrist) +
                             chain(Role::kRightShoulder, Role::kRightElbow) +
                             chain(Role::kRightElbow, Role::kRightWrist));
  body.trunk_length_m = chain(Role::kHips, Role::kHead);
  const int left_hip = roles[Role::kLeftHip], right_hip = roles[Role::kRightHip];
  if (left_hip >= 0 && right_hip >= 0 && left_hip < n && right_hip < n) {
    body.hip_width_m = metres_per_unit * (positions[static_cast<std::size_t>(left_hip)] -
                                          positions[static_cast<std::size_t>(right_hip)])
                                             .norm();
  }
  // Ankle to head joint: the leg, the drop from the hips role to the hip joints (vertical part of
  // the pelvis bone), and the trunk.
  double pelvis_drop = 0.0;
  const int hips = roles[Role::kHips];
  if (hips >= 0 && left_hip >= 0 && right_hip >= 0 && hips < n && left_hip < n && right_hip < n) {
    const Vec3 mid = 0.5 * (positions[static_cast<std::size_t>(left_hip)] +
                            positions[static_cast<std::size_t>(right_hip)]);
    const Vec3 down = mid - positions[static_cast<std::size_t>(hips)];
    // Only the part along the trunk counts (the rest pose may lean); trunk axis = hips -> head.
    const int head = roles[Role::kHead];
    if (head >= 0 && head < n) {
      const Vec3 axis = positions[static_cast<std::size_t>(head)] - positions[static_cast<std::size_t>(hips)];
      if (axis.norm() > 0.0) pelvis_drop = std::abs(down.dot(axis.normalized()));
    }
    pelvis_drop *= metres_per_unit;
  }
  body.standing_height_m =
      kHeightPerChainLength * (body.leg_length_m + pelvis_drop + body.trunk_length_m);
  return body;
}

namespace {

bool has_hips(std::span<const Vec3> positions_ws, const JointRoles& roles) noexcept {
  const int left = roles[Role::kLeftHip], right = roles[Role::kRightHip];
  return left >= 0 && right >= 0 &&
         static_cast<std::size_t>(std::max(left, right)) < positions_ws.size();
}

}  // namespace

double body_heading_yaw(std::span<const Vec3> positions_ws, const JointRoles& roles) noexcept {
  if (!has_hips(positions_ws, roles)) return std::numeric_limits<double>::quiet_NaN();
  auto horizontal_unit = [](Vec3 v) {
    v.y() = 0.0;
    const double n = v.norm();
    return n > 1e-9 ? Vec3(v / n) : Vec3::Zero();
  };
  auto at = [&](Role r) { return positions_ws[static_cast<std::size_t>(roles[r])]; };
  // Left-pointing lines of the hips and, where the rig has them, the shoulders. Salsa hips and
  // shoulders counter-rotate about the spine, so their mean turns far less than either: the
  // heading the partner is placed in and the features are read in stays steady.
  Vec3 leftward = horizontal_unit(at(Role::kLeftHip) - at(Role::kRightHip));
  const int left_shoulder = roles[Role::kLeftShoulder], right_shoulder = roles[Role::kRightShoulder];
  if (left_shoulder >= 0 && right_shoulder >= 0 &&
      static_cast<std::size_t>(std::max(left_shoulder, right_shoulder)) < positions_ws.size()) {
    leftward += horizontal_unit(at(Role::kLeftShoulder) - at(Role::kRightShoulder));
  }
  // Facing = left-pointing vector x up: a body facing +Z has its left at +X (Y up, right-handed).
  const Vec3 facing = leftward.cross(Vec3::UnitY());
  return std::atan2(facing.x(), facing.z());
}

Vec3 pelvis_centre(std::span<const Vec3> positions_ws, const JointRoles& roles) noexcept {
  if (!has_hips(positions_ws, roles))
    return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  return 0.5 * (positions_ws[static_cast<std::size_t>(roles[Role::kLeftHip])] +
                positions_ws[static_cast<std::size_t>(roles[Role::kRightHip])]);
}

}  // namespace duet
