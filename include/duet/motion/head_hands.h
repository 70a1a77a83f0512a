// Three tracked points, as a VR headset and two controllers give them (issue 12): the head's and
// both hands' positions and orientations, in metres, Y up, right-handed. Duet carries them as a
// motion on a tiny skeleton (an origin and three children), so every reader, source and recorder
// that moves a skeleton moves three points too.
//
// Orientation convention (the devices', WebXR's and OpenXR's): the head's identity faces -Z with
// +Y up; a hand's is the grip space of duet/motion/device_points.h (+Y from the fist toward the
// arm). From a full-body take, the head's orientation is its joint's world rotation relative to
// the rest pose, turned so the rest pose faces -Z: a dancer standing in the rest pose looks
// straight ahead. A rig whose rest pose is no standing body turns the head, on average over the
// take, to where its pelvis faces instead (head_correction). A hand's grip frame turns with the
// wrist joint, its +Y along the wrist's bone toward the arm.
#pragma once

#include <array>
#include <limits>
#include <memory>

#include "duet/base/result.h"
#include "duet/motion/clip.h"
#include "duet/motion/device_points.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

// Joint indices of the head-and-hands skeleton.
enum HeadHandsJoint : int { kPointsOrigin = 0, kPointsHead, kPointsLeftHand, kPointsRightHand };
constexpr int kHeadHandsJointCount = 4;

// The skeleton: "origin" (the root, never moved) with children "head", "left_hand" and
// "right_hand", each animated by position and rotation channels.
std::shared_ptr<const Skeleton> make_head_hands_skeleton();
// Its roles: head, left_wrist and right_wrist; convention "head-hands"; every other role -1.
JointRoles head_hands_roles();
// Whether `roles` describe three points only (a head and two hands, no hips): the input a
// headset gives, which the follower follows with InputPoints::kHeadHands.
bool is_head_hands_input(const JointRoles& roles);

// The rotation that takes a point's world rotation to the canonical body frame (x left, y up,
// z forward): R_canonical = R_world * correction. For a head-and-hands skeleton it is the device
// convention's half turn about Y; for a full-body rig, the heading of its rest pose (whose world
// rotations are the identity).
Quat head_hands_device_correction();
Result<Quat> rest_pose_correction(const Skeleton& skeleton, const JointRoles& roles);

// Whether a full-body rig's rest pose (every rotation the identity) is a standing body, the
// premise of rest_pose_correction: both ankles well below the pelvis and the head above it, after
// the rig's up turn. The Bandai rig's rest pose is not (every bone along one axis, one leg up):
// its rest heading put the head of its own clips 40-50 degrees off the pelvis's heading.
bool rest_pose_stands(const Skeleton& skeleton, const JointRoles& roles);

// The head's correction for a full-body clip: rest_pose_correction when the rest pose stands,
// otherwise the one that turns the head, on average over the clip, to the pelvis's heading (a
// dancer looks where the body faces, give or take a turn of the head).
Result<Quat> head_correction(const Clip& full_body, const JointRoles& roles);

// Each hand's grip frame (duet/motion/device_points.h) in the rest pose, left then right, rigid
// with its wrist joint from then on: R_grip = R_wrist_world * this. +Y along the wrist's bone
// toward the arm; the palm's normal the rig's down made square to it (a T-pose's palms face the
// floor), or its backward when the bone is near vertical; +X out of the back of the right hand,
// out of the palm of the left. Errors: a wrist with no bone to its arm.
Result<std::array<Quat, 2>> rest_grip_frames(const Skeleton& skeleton, const JointRoles& roles);

// The three points of a full-body clip (any rig with head and wrist roles), on the head-and-hands
// skeleton, at the clip's rate: what a headset and controllers held `offsets` from the joints
// would have reported (device_points_to_joints takes the offsets out again). The head's
// orientation goes through head_correction.
Result<Clip> head_hands_clip(const Clip& full_body, const JointRoles& roles,
                             const DevicePointOffsets& offsets = {});

// The highest the head joint holds over a clip's first `frames` frames (all by default), metres
// above the floor, y up: the highest median of its height over half a second (the whole clip when
// shorter), so a hop or a sensor's spike does not count. Over a whole dance, a standing
// calibration of the performer's head height (0 when no frame has a finite head). Any rig with a
// head role, three points included.
double highest_head_m(const Clip& clip, const JointRoles& roles,
                      int frames = std::numeric_limits<int>::max());

}  // namespace duet
