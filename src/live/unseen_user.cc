#include "duet/live/unseen_user.h"

#include "duet/partner/alignment.h"

namespace duet {
namespace {

// The frame the user's body is placed by: the body heading when known, else the root's.
Transform body_frame(const UserPose& user) noexcept {
  return user.body_heading_valid
             ? user.body_heading
             : heading_frame(user.root_position_ws, user.root_rotation_ws.normalized());
}

}  // namespace

void UnseenUser::seen(const UserPose& user, const Transform& template_heading, int take) noexcept {
  const Transform body = body_frame(user);
  if (!body.translation.allFinite() || !body.rotation.coeffs().allFinite() ||
      !template_heading.translation.allFinite() || !template_heading.rotation.coeffs().allFinite()) {
    take_ = -1;
    return;
  }
  last_ = user;
  template_heading_ = template_heading;
  take_ = take;
}

bool UnseenUser::carry(UserPose& user, const Transform& template_heading, int take) const noexcept {
  if (take_ < 0 || take != take_) return false;
  // The template dancer's move between the two frames, in its heading frame at the first; the
  // same move of the user's body frame, as a world transform of everything the body carries.
  const Transform move = template_heading_.inverse() * template_heading;
  const Transform body = body_frame(last_);
  const Transform world = body * move * body.inverse();
  if (!world.translation.allFinite() || !world.rotation.coeffs().allFinite()) return false;
  user.root_position_ws = world.apply(last_.root_position_ws);
  user.root_rotation_ws = (world.rotation * last_.root_rotation_ws).normalized();
  user.body_heading = world * body;
  user.body_heading_valid = true;
  for (std::size_t s = 0; s < 2; ++s) {
    user.wrist_positions_ws[s] = world.apply(last_.wrist_positions_ws[s]);
    user.wrist_rotations_ws[s] = (world.rotation * last_.wrist_rotations_ws[s]).normalized();
  }
  return true;
}

bool UnseenUser::hold_hands(UserPose& user, const std::array<bool, 2>& unseen) const noexcept {
  if (take_ < 0) return false;
  const Transform onto_seen = body_frame(user) * body_frame(last_).inverse();
  if (!onto_seen.translation.allFinite() || !onto_seen.rotation.coeffs().allFinite()) return false;
  for (std::size_t s = 0; s < 2; ++s) {
    if (!unseen[s]) continue;
    user.wrist_positions_ws[s] = onto_seen.apply(last_.wrist_positions_ws[s]);
    user.wrist_rotations_ws[s] = (onto_seen.rotation * last_.wrist_rotations_ws[s]).normalized();
  }
  return true;
}

}  // namespace duet
