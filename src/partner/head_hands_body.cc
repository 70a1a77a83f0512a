#include "duet/partner/head_hands_body.h"

#include <algorithm>
#include <cmath>

#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"
#include "duet/partner/alignment.h"

namespace duet {

Transform head_heading_frame(const Vec3& head_position_ws, const Quat& head_canonical_ws) noexcept {
  Transform frame;
  frame.rotation = yaw_rotation(heading_yaw(head_canonical_ws));
  frame.translation = Vec3(head_position_ws.x(), 0.0, head_position_ws.z());
  return frame;
}

Result<HeadHandsBody> HeadHandsBody::build(const Clip& template_clip,
                                           const JointRoles& template_roles) {
  const int head = template_roles[Role::kHead];
  if (head < 0 || head >= template_clip.joint_count()) {
    return Error{"the template has no head joint (role head)"};
  }
  const std::array<int, 2> wrists = {template_roles[Role::kLeftWrist],
                                     template_roles[Role::kRightWrist]};
  for (const int wrist : wrists) {
    if (wrist < 0 || wrist >= template_clip.joint_count()) {
      return Error{"the template has no wrist joint (roles left_wrist and right_wrist)"};
    }
  }
  Result<Quat> correction = head_correction(template_clip, template_roles);
  if (!correction) return Error{"the template: " + correction.error().message};
  HeadHandsBody body;
  Result<std::array<Quat, 2>> grips = rest_grip_frames(template_clip.skeleton(), template_roles);
  if (!grips) return Error{"the template: " + grips.error().message};
  body.rest_grips_ = grips.value();
  body.head_in_body_.resize(static_cast<std::size_t>(template_clip.frame_count()));
  body.wrists_in_body_.resize(static_cast<std::size_t>(template_clip.frame_count()));
  const auto n = static_cast<std::size_t>(template_clip.joint_count());
  std::vector<Vec3> positions(n);
  std::vector<Quat> rotations(n);
  const auto h = static_cast<std::size_t>(head);
  for (int f = 0; f < template_clip.frame_count(); ++f) {
    forward_kinematics(template_clip.skeleton(), template_clip.translations_ls(f),
                       template_clip.rotations_ls(f), positions, rotations);
    const Transform head_frame = head_heading_frame(positions[h], rotations[h] * correction.value());
    const Transform body_frame = body_heading_frame(positions, template_roles);
    body.head_in_body_[static_cast<std::size_t>(f)] = body_frame.inverse() * head_frame;
    for (std::size_t s = 0; s < 2; ++s) {
      body.wrists_in_body_[static_cast<std::size_t>(f)][s] =
          body_frame.inverse().apply(positions[static_cast<std::size_t>(wrists[s])]);
    }
    body.template_head_height_m_ = std::max(body.template_head_height_m_, positions[h].y());
  }
  return body;
}

Transform HeadHandsBody::body_heading(const Transform& user_head_heading, int frame,
                                      double size_ratio) const noexcept {
  if (head_in_body_.empty()) return user_head_heading;
  const auto f = static_cast<std::size_t>(std::clamp(frame, 0, frame_count() - 1));
  Transform relation = head_in_body_[f];
  if (std::isfinite(size_ratio) && size_ratio > 0.0) relation.translation *= size_ratio;
  return user_head_heading * relation.inverse();
}

std::array<Vec3, 2> HeadHandsBody::wrist_size_difference_hs(double frame_position,
                                                            double size_ratio) const noexcept {
  std::array<Vec3, 2> difference = {Vec3::Zero(), Vec3::Zero()};
  if (wrists_in_body_.empty() || !std::isfinite(size_ratio) || !(size_ratio > 0.0) ||
      !std::isfinite(frame_position)) {
    return difference;
  }
  const double last = static_cast<double>(frame_count() - 1);
  const double at = std::clamp(frame_position, 0.0, last);
  const auto below = static_cast<std::size_t>(std::floor(at));
  const std::size_t above = std::min(below + 1, wrists_in_body_.size() - 1);
  const double share = at - static_cast<double>(below);
  for (std::size_t s = 0; s < 2; ++s) {
    const Vec3 wrist =
        (1.0 - share) * wrists_in_body_[below][s] + share * wrists_in_body_[above][s];
    difference[s] = (size_ratio - 1.0) * wrist;
  }
  return difference;
}

}  // namespace duet
