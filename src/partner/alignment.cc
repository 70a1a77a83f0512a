#include "duet/partner/alignment.h"

#include <cassert>
#include <string>

#include "duet/math/rotation.h"

namespace duet {

Transform heading_frame(const Vec3& root_position_ws, const Quat& root_rotation_ws) noexcept {
  return {yaw_rotation(heading_yaw(root_rotation_ws)),
          Vec3(root_position_ws.x(), 0.0, root_position_ws.z())};
}

double RootPlacement::relative_yaw_rad() const noexcept {
  return wrap_angle(heading_yaw(rotation_hs));
}

Transform place_root(const RootPlacement& placement, const Vec3& user_root_position_ws,
                     const Quat& user_root_rotation_ws) noexcept {
  const Transform user = heading_frame(user_root_position_ws, user_root_rotation_ws);
  Transform root = user * Transform{placement.rotation_hs, placement.position_hs};
  root.rotation.normalize();
  return root;
}

Result<SpatialAlignment> SpatialAlignment::build(const Clip& template_clip,
                                                 const Clip& response_clip) {
  if (template_clip.frame_count() != response_clip.frame_count()) {
    return Error{"spatial alignment: the template has " +
                 std::to_string(template_clip.frame_count()) + " frames, the response " +
                 std::to_string(response_clip.frame_count()) + " (a duet needs the same count)"};
  }
  if (template_clip.frame_count() <= 0 || template_clip.joint_count() <= 0 ||
      response_clip.joint_count() <= 0) {
    return Error{"spatial alignment: the duet has no frames or no joints"};
  }
  SpatialAlignment alignment;
  alignment.placements_.resize(static_cast<std::size_t>(template_clip.frame_count()));
  for (int f = 0; f < template_clip.frame_count(); ++f) {
    const Transform tmpl =
        heading_frame(template_clip.translations_ls(f)[0], template_clip.rotations_ls(f)[0]);
    const Transform resp{response_clip.rotations_ls(f)[0], response_clip.translations_ls(f)[0]};
    const Transform rel = tmpl.inverse() * resp;
    if (!rel.translation.allFinite() || !rel.rotation.coeffs().allFinite()) {
      return Error{"spatial alignment: frame " + std::to_string(f) +
                   " has a non-finite root transform"};
    }
    alignment.placements_[static_cast<std::size_t>(f)] = {rel.translation,
                                                          rel.rotation.normalized()};
  }
  return alignment;
}

const RootPlacement& SpatialAlignment::placement(int frame) const noexcept {
  assert(frame >= 0 && frame < frame_count());
  return placements_[static_cast<std::size_t>(frame)];
}

RootPlacement SpatialAlignment::placement_at(double frame) const noexcept {
  const auto [f0, f1, w] = bracket_frame(frame, frame_count());
  const RootPlacement& p0 = placements_[static_cast<std::size_t>(f0)];
  const RootPlacement& p1 = placements_[static_cast<std::size_t>(f1)];
  RootPlacement placement;
  placement.position_hs = (1.0 - w) * p0.position_hs + w * p1.position_hs;
  placement.rotation_hs = p0.rotation_hs.slerp(w, p1.rotation_hs).normalized();
  return placement;
}

}  // namespace duet
