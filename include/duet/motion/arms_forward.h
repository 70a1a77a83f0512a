// Three points' body calibration (issue 10): where a body's wrists are with both arms held
// straight forward, relative to its head.
//
// Three points' posture features are the hands' places relative to the head (docs/features.md).
// Two bodies in the same pose do not put their hands at the same places: the CMU ASF rig's
// shoulders are 0.30 head heights apart where the salsa BVH's are 0.16, and the CMU handshake
// rig's head sits 0.05 head heights further forward of its hands. Each is a near-constant offset
// of every hand place, which left the same performance 8-25 points under the library's rig.
// Measured once, in a pose both bodies can take, it can be taken out: standing straight with
// both arms held straight forward, the wrists sit at the shoulders plus the arm's length forward.
// A headset user holds the pose (duet follow --calibration, the viewer's calibration); a
// full-body rig (the library's templates, the evaluation's performers) is measured from its
// skeleton and motion, the same way on both sides.
#pragma once

#include <array>
#include <span>
#include <string>

#include "duet/base/result.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

struct ArmsForward {
  // Left then right wrist, relative to the head joint in the head's heading frame (x left, y up,
  // z forward), in head heights standing.
  std::array<Vec3, 2> wrists{Vec3::Zero(), Vec3::Zero()};

  // Empty when the wrists are where arms held forward can put them: in front of the head
  // (0.15-1 head heights), left on the left, at most 0.7 head heights apart, between 0.6 below
  // and 0.3 above the head; otherwise what is wrong, for an error message.
  std::string check() const;
};

// A full-body rig in its own motion: per side, the median over every `stride`-th frame of the
// shoulder (upper-arm) joint relative to the head joint in the head's heading frame, plus the
// arm's length (shoulder to elbow to wrist) forward, in head heights (highest_head_m). The head's
// frame is its world rotation times head_correction (head_hands.h). Errors: the rig lacks the
// roles, or no frame is finite.
Result<ArmsForward> arms_forward_of_body(const Clip& full_body, const JointRoles& roles,
                                         int stride = 1);
// The same with the head's correction given (a caller that has head_correction already).
Result<ArmsForward> arms_forward_of_body(const Clip& full_body, const JointRoles& roles,
                                         const Quat& head_correction, int stride);

// Three points (the head-and-hands skeleton, head_hands.h, device offsets taken out) of a user
// holding the pose: the median over frames of each wrist relative to the head in the head's
// heading frame, in units of `head_height` (in the clip's units; 0: median_head_height, the
// user standing straight). Errors: no finite frame, or a pose arms held forward cannot give
// (ArmsForward::check).
Result<ArmsForward> arms_forward_of_points(const Clip& points, double head_height = 0.0);

// The head point's median height over a three-point clip's frames (the clip's units): standing
// straight in the pose, the head's height standing. 0 when no frame is finite.
double median_head_height(const Clip& points);

// Per wrist and coordinate, the median of several bodies' (a library's takes); `poses` not empty.
ArmsForward median_arms_forward(std::span<const ArmsForward> poses);

}  // namespace duet
