#include "duet/partner/alignment.h"

#include <cassert>
#include <string>

#include "duet/math/rotation.h"
#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"

namespace duet {

Transform heading_frame(const Vec3& root_position_ws, const Quat& root_rotation_ws) noexcept {
  return {yaw_rotation(heading_yaw(root_rotation_ws)),
          Vec3(root_position_ws.x(), 0.0, root_position_ws.z())};
}

Transform body_heading_frame(std::span<const Vec3> positions_ws, const JointRoles& roles) noexcept {
  const Vec3 pelvis = pelvis_centre(positions_ws, roles);
  return {yaw_rotation(body_heading_yaw(positions_ws, roles)), Vec3(pelvis.x(), 0.0, pelvis.z())};
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

namespace {

// The placements of the response root in the template's heading frame at every frame, whichever
// way that frame is taken (`template_frame(f)`).
template <typename TemplateFrame>
Result<std::vector<RootPlacement>> placements(const Clip& template_clip, const Clip& response_clip,
                                              TemplateFrame template_frame,
                                              std::vector<Transform>& template_headings) {
  if (template_clip.frame_count() != response_clip.frame_count()) {
    return Error{"spatial alignment: the template has " +
                 std::to_string(template_clip.frame_count()) + " frames, the response " +
                 std::to_string(response_clip.frame_count()) + " (a duet needs the same count)"};
  }
  if (template_clip.frame_count() <= 0 || template_clip.joint_count() <= 0 ||
      response_clip.joint_count() <= 0) {
    return Error{"spatial alignment: the duet has no frames or no joints"};
  }
  std::vector<RootPlacement> out(static_cast<std::size_t>(template_clip.frame_count()));
  template_headings.assign(out.size(), Transform{});
  for (int f = 0; f < template_clip.frame_count(); ++f) {
    const Transform tmpl = template_frame(f);
    template_headings[static_cast<std::size_t>(f)] = tmpl;
    const Transform resp{response_clip.rotations_ls(f)[0], response_clip.translations_ls(f)[0]};
    const Transform rel = tmpl.inverse() * resp;
    if (!rel.translation.allFinite() || !rel.rotation.coeffs().allFinite()) {
      return Error{"spatial alignment: frame " + std::to_string(f) +
                   " has a non-finite root transform"};
    }
    out[static_cast<std::size_t>(f)] = {rel.translation, rel.rotation.normalized()};
  }
  return out;
}

}  // namespace

Result<SpatialAlignment> SpatialAlignment::build(const Clip& template_clip,
                                                 const Clip& response_clip) {
  SpatialAlignment alignment;
  Result<std::vector<RootPlacement>> made = placements(
      template_clip, response_clip,
      [&](int f) {
        return heading_frame(template_clip.translations_ls(f)[0], template_clip.rotations_ls(f)[0]);
      },
      alignment.template_headings_);
  if (!made) return made.error();
  alignment.placements_ = std::move(made).value();
  return alignment;
}

Result<SpatialAlignment> SpatialAlignment::build(const Clip& template_clip,
                                                 const JointRoles& template_roles,
                                                 const Clip& response_clip) {
  for (Role role : {Role::kLeftHip, Role::kRightHip}) {
    if (template_roles[role] < 0 || template_roles[role] >= template_clip.joint_count()) {
      return Error{"spatial alignment: the template has no joint for role " +
                   std::string(role_name(role))};
    }
  }
  const std::vector<Vec3> positions = world_positions(template_clip);
  const auto n = static_cast<std::size_t>(template_clip.joint_count());
  SpatialAlignment alignment;
  Result<std::vector<RootPlacement>> made = placements(
      template_clip, response_clip,
      [&](int f) {
        return body_heading_frame(
            std::span<const Vec3>(positions.data() + static_cast<std::size_t>(f) * n, n),
            template_roles);
      },
      alignment.template_headings_);
  if (!made) return made.error();
  alignment.placements_ = std::move(made).value();
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

Transform SpatialAlignment::template_heading_at(double frame) const noexcept {
  const auto [f0, f1, w] = bracket_frame(frame, static_cast<int>(template_headings_.size()));
  const Transform& h0 = template_headings_[static_cast<std::size_t>(f0)];
  const Transform& h1 = template_headings_[static_cast<std::size_t>(f1)];
  return {h0.rotation.slerp(w, h1.rotation).normalized(),
          (1.0 - w) * h0.translation + w * h1.translation};
}

}  // namespace duet
