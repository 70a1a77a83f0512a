// A rig-independent view of a body (issue 10): its dimensions and its heading, measured from the
// joints that play the body roles, never from joint names, rest-pose rotations or joint-local
// axes. Two rigs that pose the same body the same way give the same numbers here.
#pragma once

#include <span>

#include "duet/motion/skeleton.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

// Lengths along the bones between roles, summed over every joint in between, so a rig with a
// twist joint in the forearm or three spine joints measures like one with one. From the rest
// offsets only: the rest pose (T, A or anything else) does not matter.
struct BodyDimensions {
  double leg_length_m = 0.0;    // hip joint -> knee -> ankle, mean of both sides
  double arm_length_m = 0.0;    // shoulder (upper arm) -> elbow -> wrist, mean of both sides
  double trunk_length_m = 0.0;  // hips -> ... -> head joint
  double hip_width_m = 0.0;     // left hip joint to right hip joint (straight, at rest)
  // Estimated standing height: ankle to head joint along the bones, plus the typical share of the
  // ankle height and the skull above the head joint (docs/rigs.md says how it was calibrated).
  double standing_height_m = 0.0;

  bool valid() const { return leg_length_m > 0.0 && trunk_length_m > 0.0; }
};

// `metres_per_unit` scales the skeleton's offsets (1 when the skeleton is already in metres).
BodyDimensions measure_body(const Skeleton& skeleton, const JointRoles& roles,
                            double metres_per_unit = 1.0);

// The body's heading (yaw about +Y, the convention of duet::heading_yaw: 0 faces +Z) from world
// joint positions: the facing is perpendicular to the mean of the hip line and the shoulder line
// (right to left, on the floor; the hips alone when the shoulders have no joint). Independent of
// the root joint's axes. NaN when the rig has no hip joints (roles missing or outside positions_ws)
// or the hips stand at one place.
double body_heading_yaw(std::span<const Vec3> positions_ws, const JointRoles& roles) noexcept;

// The pelvis centre: the midpoint of the two hip (thigh) joints, which sit at the same place on
// every rig, unlike the root joint. NaN when the rig has no hip joints.
Vec3 pelvis_centre(std::span<const Vec3> positions_ws, const JointRoles& roles) noexcept;

}  // namespace duet
