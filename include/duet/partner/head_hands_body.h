// Where the body of a user tracked by three points is (issue 12). The partner is placed relative
// to the user's body heading frame (the pelvis centre on the floor, turned by the hips' heading),
// which a headset and two controllers do not show. At the template frame the follower estimates,
// the captured dancer's head stood at a known place and yaw in their own body heading frame; the
// user's body heading frame is the user's head frame with that relation undone (scaled to the
// user's size). Dancing as the template danced, that puts the user's hips where they are.
#pragma once

#include <array>
#include <vector>

#include "duet/base/result.h"
#include "duet/math/types.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

// A head's heading frame: its position on the floor (y = 0), turned about +Y by the facing of its
// canonical orientation (R_world * correction, duet/motion/head_hands.h).
Transform head_heading_frame(const Vec3& head_position_ws, const Quat& head_canonical_ws) noexcept;

class HeadHandsBody {
 public:
  HeadHandsBody() = default;
  // Offline, per duet take: the template's head frame in its body heading frame at every frame.
  static Result<HeadHandsBody> build(const Clip& template_clip, const JointRoles& template_roles);

  int frame_count() const noexcept { return static_cast<int>(head_in_body_.size()); }
  // The highest the template's head was (metres): the size the user's head height is compared to.
  double template_head_height_m() const noexcept { return template_head_height_m_; }
  // What the template's wrist would have been turned to holding a controller at `grip_ws` (its
  // grip space, duet/motion/device_points.h): R_wrist = R_grip * rest grip frame^-1 of the
  // template's rig, so the captured grip offset, carried in the template wrist's frame, can be
  // carried by a controller. `left_hand` picks the hand.
  Quat template_wrist_rotation(bool left_hand, const Quat& grip_ws) const noexcept {
    return (grip_ws * rest_grips_[left_hand ? 0 : 1].conjugate()).normalized();
  }

  // The user's body heading frame from their head's heading frame at template frame `frame`
  // (clamped to the take), for a user `size_ratio` times the template's size.
  Transform body_heading(const Transform& user_head_heading, int frame,
                         double size_ratio) const noexcept;

  // Where the same scaled body (a user `size_ratio` times the template's size, dancing it
  // exactly) puts its wrists beyond the template's, at real frame `frame_position` (clamped to the
  // take), each in its body heading frame, indexed by Side: (size_ratio - 1) times the template's
  // wrists there. The contact IK takes this part of the hand's difference whole
  // (UserPose::wrist_body_difference_hs); zero for a ratio that is not finite and positive.
  std::array<Vec3, 2> wrist_size_difference_hs(double frame_position,
                                               double size_ratio) const noexcept;

 private:
  std::vector<Transform> head_in_body_;
  std::vector<std::array<Vec3, 2>> wrists_in_body_;  // left, right, per frame
  double template_head_height_m_ = 0.0;
  std::array<Quat, 2> rest_grips_ = {Quat::Identity(), Quat::Identity()};  // left, right
};

}  // namespace duet
