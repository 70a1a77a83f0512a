// Analytic two-bone inverse kinematics (Tolani, Goswami and Badler 2000; method.md 5.2): moves the
// end of a three-joint chain (shoulder -> elbow -> wrist) to a target.
//
// 1. Elbow: the interior angle at the middle joint comes from the law of cosines for the
//    shoulder-to-target distance; the middle joint turns about its current hinge axis (the
//    normal of the plane through the three joints), so the forearm bends in its own plane.
// 2. Swivel: the start joint then turns along the shortest arc that carries the
//    shoulder-to-wrist direction onto the shoulder-to-target direction. The swivel angle of the
//    elbow about that axis is therefore the one of the current pose carried along, not a fixed
//    default as in the paper: the elbow does not flip as the target moves (beyond, method.md
//    5.2). `swivel_offset_rad` adds a rotation about the shoulder-to-target axis.
// 3. A target out of reach is clamped: farther than the sum of the bones, the chain stretches
//    straight towards it; closer than their difference, the chain folds as far as it can. The
//    job never produces NaN, also for a target at the shoulder or zero-length bones.
//
// A plain struct in the style of ozz-animation's IKTwoBoneJob: the caller sets the inputs, owns
// every buffer and calls run(); nothing is allocated and nothing throws, so it runs on the
// per-frame path.
#pragma once

#include <limits>
#include <string_view>

#include "duet/math/types.h"

namespace duet {

struct IkTwoBoneJob {
  // ---- Inputs (pointers are not owned and must outlive run()) ----

  // World transforms (_ws) of the chain's joints: start (shoulder: the upper-arm joint), mid
  // (elbow: the forearm joint) and end (wrist: the hand joint). mid must be a descendant of start
  // and end of mid, not necessarily direct children (joints in between stay as they are). Only
  // the end joint's position is used.
  const Transform* start_joint_ws = nullptr;
  const Transform* mid_joint_ws = nullptr;
  const Transform* end_joint_ws = nullptr;

  // Current local rotations (_ls, relative to the parent) of the start and mid joints; the job
  // outputs them corrected. They must be the rotations that produced the world transforms above.
  const Quat* start_rotation_ls = nullptr;
  const Quat* mid_rotation_ls = nullptr;

  // Where the end joint should go, world space. NaN until set: validate() fails on it.
  Vec3 target_ws = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());

  // Blend from no correction (0) to full IK (1); clamped to [0, 1]. The corrections are slerped
  // from identity, so intermediate weights move the wrist along a smooth path.
  double weight = 1.0;

  // Extra rotation of the solved chain about the shoulder-to-target axis, radians (right-hand
  // rule). 0 keeps the swivel of the current pose.
  double swivel_offset_rad = 0.0;

  // Soft reach (Harris 2012): the share of the chain's full length (upper + lower bone) over
  // which reaching out to full extension is eased. Near a straight chain the law of cosines turns
  // the elbow ever faster per centimetre of target distance (infinitely fast at full extension),
  // so a target jittering at the edge of the reach snaps the elbow. With a soft share s, a
  // target beyond (1 - s) of the length is reached to (1 - s) L + s L (1 - exp(-excess / (s L))):
  // the chain approaches straight smoothly and falls short by at most the excess. 0: off.
  double soft_reach = 0.0;

  // ---- Outputs (owned by the caller; may alias start_rotation_ls / mid_rotation_ls) ----

  // Corrected local rotations of the start and mid joints.
  Quat* start_rotation_ls_out = nullptr;
  Quat* mid_rotation_ls_out = nullptr;

  // Optional: true when the end joint lands on the target (within 1e-6 of the chain length),
  // i.e. the target is within reach and weight is 1.
  bool* reached = nullptr;
  // Optional: where the end joint lands after the correction, world space.
  Vec3* end_position_ws = nullptr;

  // Empty when the job can run; otherwise what is wrong ("start_joint_ws is null", "target_ws is
  // not finite (not set?)", ...). Checks pointers and that every number is finite.
  std::string_view validate() const noexcept;

  // Validates, then solves. Returns false (outputs untouched) when validate() fails.
  bool run() const noexcept;
};

}  // namespace duet
