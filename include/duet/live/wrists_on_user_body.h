// Where the user's wrists would be dancing the template exactly, on their own body (issue 10).
//
// The contact IK aims the partner's hand at the captured partner's wrist plus what the user's
// sensed hand differs by from the template dancer's, averaged against the sensor's noise
// (SteadyDifference). Part of that difference is the two bodies: a rig whose arms sit otherwise
// against the pelvis puts the user's hand centimetres from the template dancer's in the same
// pose (4.7 and 6.3 cm on the CMU ASF and handshake rigs, placed by the alignment alone), and
// changes with the pose. Averaged from a noisy sensor, that part lagged and was doubted: the
// hands at contacts 2.4 cm apart at 1.1x with 3 degrees of noise on those rigs. It is known
// exactly from the two skeletons: the template's pose at the partner's frame, retargeted onto the
// user's skeleton (Retargeter), puts the user's wrists where their body takes them; the
// difference from the template dancer's wrists, each in its body's heading frame, is the bodies'
// part, and only the rest (the user's own way of dancing, the sensor's noise) is averaged.
#pragma once

#include <array>
#include <vector>

#include "duet/base/result.h"
#include "duet/io/motion_file.h"
#include "duet/live/source_frame.h"
#include "duet/motion/clip.h"
#include "duet/motion/retarget.h"

namespace duet {

class WristsOnUserBody {
 public:
  // One retargeting per take, from its template dancer's skeleton onto the user's (both in
  // metres). `dancers` (a library's takes' template motions, DuetTake::template_motion) must
  // outlive this. Fails when a skeleton lacks the roles retargeting needs.
  static Result<WristsOnUserBody> create(std::vector<const LoadedMotion*> dancers,
                                         const SourceSkeleton& user);

  // The user's wrists (indexed by Side) dancing take `take` at real frame `frame_position` exactly,
  // less the template dancer's there, each relative to its body's heading frame
  // (body_heading_frame). Zero for a take out of range. Allocates nothing.
  std::array<Vec3, 2> wrist_difference_hs(int take, double frame_position) noexcept;

 private:
  std::vector<const LoadedMotion*> dancers_;
  JointRoles user_roles_;
  std::vector<Retargeter> retargeters_;  // per take
  Pose template_pose_;
  std::vector<Vec3> template_positions_ws_;
  std::vector<Quat> template_rotations_ws_;
  std::vector<Vec3> user_translations_ls_;
  std::vector<Quat> user_rotations_ls_;
  std::vector<Vec3> user_positions_ws_;
  std::vector<Quat> user_rotations_ws_;
};

}  // namespace duet
