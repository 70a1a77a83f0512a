#include "duet/live/wrists_on_user_body.h"

#include <algorithm>
#include <string>

#include "duet/motion/forward_kinematics.h"
#include "duet/partner/alignment.h"
#include "duet/partner/hand_contacts.h"

namespace duet {
namespace {

// The wrists (by Side) relative to the body's heading frame.
std::array<Vec3, 2> wrists_hs(std::span<const Vec3> positions_ws, const JointRoles& roles) {
  const Transform heading = body_heading_frame(positions_ws, roles).inverse();
  std::array<Vec3, 2> wrists;
  for (const Side side : {Side::kLeft, Side::kRight}) {
    const int joint = roles[side == Side::kLeft ? Role::kLeftWrist : Role::kRightWrist];
    wrists[static_cast<std::size_t>(side)] =
        heading.apply(positions_ws[static_cast<std::size_t>(joint)]);
  }
  return wrists;
}

}  // namespace

Result<WristsOnUserBody> WristsOnUserBody::create(std::vector<const LoadedMotion*> dancers,
                                                  const SourceSkeleton& user) {
  WristsOnUserBody wrists;
  wrists.user_roles_ = user.roles;
  int template_joints = 0;
  for (std::size_t take = 0; take < dancers.size(); ++take) {
    const LoadedMotion& dancer = *dancers[take];
    Result<Retargeter> retargeter = Retargeter::create(
        dancer.clip.skeleton_ptr(), dancer.roles, user.skeleton, user.roles, {},
        "the template dancer of take " + std::to_string(take), "the user's skeleton");
    if (!retargeter) return retargeter.error();
    wrists.retargeters_.push_back(std::move(retargeter).value());
    template_joints = std::max(template_joints, dancer.clip.joint_count());
  }
  wrists.dancers_ = std::move(dancers);
  const auto user_joints = static_cast<std::size_t>(user.skeleton->joint_count());
  wrists.template_pose_.resize(template_joints);
  wrists.template_positions_ws_.resize(static_cast<std::size_t>(template_joints));
  wrists.template_rotations_ws_.resize(static_cast<std::size_t>(template_joints));
  wrists.user_translations_ls_.resize(user_joints);
  wrists.user_rotations_ls_.resize(user_joints);
  wrists.user_positions_ws_.resize(user_joints);
  wrists.user_rotations_ws_.resize(user_joints);
  return wrists;
}

std::array<Vec3, 2> WristsOnUserBody::wrist_difference_hs(int take,
                                                          double frame_position) noexcept {
  if (take < 0 || static_cast<std::size_t>(take) >= retargeters_.size()) {
    return {Vec3::Zero(), Vec3::Zero()};
  }
  const LoadedMotion& dancer = *dancers_[static_cast<std::size_t>(take)];
  const Clip& clip = dancer.clip;
  const auto joints = static_cast<std::size_t>(clip.joint_count());
  clip.sample(frame_position / clip.frame_rate(), template_pose_);
  const std::span<const Vec3> translations(template_pose_.translations_ls.data(), joints);
  const std::span<const Quat> rotations(template_pose_.rotations_ls.data(), joints);
  const std::span<Vec3> template_positions(template_positions_ws_.data(), joints);
  forward_kinematics(clip.skeleton(), translations, rotations, template_positions,
                     std::span<Quat>(template_rotations_ws_.data(), joints));
  Retargeter& retargeter = retargeters_[static_cast<std::size_t>(take)];
  retargeter.retarget_frame(translations, rotations, user_translations_ls_, user_rotations_ls_);
  forward_kinematics(retargeter.target(), user_translations_ls_, user_rotations_ls_,
                     user_positions_ws_, user_rotations_ws_);
  const std::array<Vec3, 2> on_template = wrists_hs(template_positions, dancer.roles);
  const std::array<Vec3, 2> on_user = wrists_hs(user_positions_ws_, user_roles_);
  return {on_user[0] - on_template[0], on_user[1] - on_template[1]};
}

}  // namespace duet
