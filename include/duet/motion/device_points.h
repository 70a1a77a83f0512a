// Where a headset and two controllers sit against the joints the follower knows, and how to take
// that out. WebXR and OpenXR report the headset at the eyes (the viewer pose) and each controller
// at its grip (the centre of the fist round the controller), not at the head and wrist joints the
// library's templates are made of. Left in, the partner holds the grips (6 cm from the real
// hands) and is placed from the eyes (docs/evaluation.md, "Devices where they sit").
//
// A controller's frame is WebXR's grip space: +Y from the fist toward the arm, +X out of the
// back of the right hand (out of the palm of the left), Z = X x Y along the controller.
#pragma once

#include <span>

#include "duet/motion/clip.h"

namespace duet {

struct DevicePointOffsets {
  // The eyes from the head joint, in the head's canonical frame (x left, y up, z forward).
  Vec3 eyes_m = Vec3::Zero();
  // The grip from the wrist joint along the hand, away from the arm (the grip frame's -Y).
  double grip_m = 0.0;

  bool any() const { return eyes_m.squaredNorm() > 0.0 || grip_m != 0.0; }
  // The eyes `forward_cm` in front of and `up_cm` above the head joint, the grips `grip_cm` past
  // the wrists: the command lines' --device-offsets-cm FORWARD,UP,GRIP.
  static DevicePointOffsets from_cm(double forward_cm, double up_cm, double grip_cm);
};

// A headset user's offsets when nothing else is known (`duet serve --source xr`): the eyes 6 cm
// in front of and 6 cm above the head joint (the salsa rig's eye joints sit at 6.3 and 6.3 cm),
// the grip 7 cm past the wrist (the rig's middle knuckle is 6.4 cm along the hand, the fist's
// centre a little further).
DevicePointOffsets typical_headset_offsets();

// Moves one frame of the head-and-hands skeleton (duet/motion/head_hands.h) from where the
// devices sit to the joints: the head joint `eyes_m` behind the eyes in the head's canonical
// frame, each wrist `grip_m` along its grip's +Y. Positions in metres. Allocates nothing.
void device_points_to_joints(const DevicePointOffsets& offsets, std::span<Vec3> translations_ls,
                             std::span<const Quat> rotations_ls) noexcept;
// The same for every frame of a three-point clip.
void device_points_to_joints(const DevicePointOffsets& offsets, Clip& points);

// The head joint's height standing from the head point's (a height calibration of the headset,
// duet follow/serve --head-height): less the eyes' height above the head joint that `offsets` say
// (the user stands straight, so the head's up is the world's). 0 (not given) stays 0.
double head_joint_height_m(double head_point_height_m, const DevicePointOffsets& offsets);
// The head point's heights standing a calibration may give (metres): a child to a tall adult.
inline constexpr double kHeadPointHeightRangeM[2] = {0.6, 2.6};

}  // namespace duet
