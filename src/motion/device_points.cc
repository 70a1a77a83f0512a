#include "duet/motion/device_points.h"

#include <cassert>

#include "duet/motion/head_hands.h"

namespace duet {

DevicePointOffsets DevicePointOffsets::from_cm(double forward_cm, double up_cm, double grip_cm) {
  DevicePointOffsets offsets;
  offsets.eyes_m = Vec3(0.0, up_cm, forward_cm) / 100.0;
  offsets.grip_m = grip_cm / 100.0;
  return offsets;
}

DevicePointOffsets typical_headset_offsets() { return DevicePointOffsets::from_cm(6.0, 6.0, 7.0); }

void device_points_to_joints(const DevicePointOffsets& offsets, std::span<Vec3> translations_ls,
                             std::span<const Quat> rotations_ls) noexcept {
  assert(translations_ls.size() == kHeadHandsJointCount &&
         rotations_ls.size() == kHeadHandsJointCount);
  // The points' parent (the origin) never moves, so local is world.
  const Quat head_canonical = rotations_ls[kPointsHead] * head_hands_device_correction();
  translations_ls[kPointsHead] -= head_canonical * offsets.eyes_m;
  for (int hand : {kPointsLeftHand, kPointsRightHand}) {
    const auto h = static_cast<std::size_t>(hand);
    translations_ls[h] += offsets.grip_m * (rotations_ls[h] * Vec3::UnitY());
  }
}

void device_points_to_joints(const DevicePointOffsets& offsets, Clip& points) {
  assert(points.joint_count() == kHeadHandsJointCount);
  for (int f = 0; f < points.frame_count(); ++f) {
    device_points_to_joints(offsets, points.translations_ls(f), points.rotations_ls(f));
  }
}

double head_joint_height_m(double head_point_height_m, const DevicePointOffsets& offsets) {
  return head_point_height_m > 0.0 ? head_point_height_m - offsets.eyes_m.y() : 0.0;
}

}  // namespace duet
