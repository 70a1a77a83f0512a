// Spatial alignment (method.md 5.1, paper 5.1): the partner is placed relative to the user, not
// at its captured place in the room.
//
// Offline, for every frame of a duet, the response's root is expressed in the template's
// heading frame: the template root projected on the floor (y = 0) and turned by its heading
// (yaw). That gives a horizontal offset, a height above the floor, and the root rotation relative
// to the template's heading (its yaw is the relative yaw; tilt and roll are the response's own).
// At run time the same relative transform is applied to the user's current heading frame, so a
// user who dances elsewhere in the room, faces elsewhere, or jumps to another part of the dance
// keeps the partner where it belongs relative to them.
//
// "Root" is joint 0 of each skeleton (the hips in every convention shipped; its local transform
// is its world transform). Heading is duet::heading_yaw() of the root's world rotation, so the
// user's root rotation must follow the template skeleton's axis convention.
#pragma once

#include <span>
#include <vector>

#include "duet/base/result.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

// A body's heading frame: its root projected on the floor (y = 0), turned about +Y by its heading.
Transform heading_frame(const Vec3& root_position_ws, const Quat& root_rotation_ws) noexcept;

// The rig-independent heading frame (issue 10): the pelvis centre (midpoint of the hip joints) on
// the floor, turned by the heading of the hip line (duet::body_heading_yaw). The same body on any
// rig, whatever its root joint's place and axes, gets the same frame.
Transform body_heading_frame(std::span<const Vec3> positions_ws, const JointRoles& roles) noexcept;

// The response root relative to the template's heading frame (_hs: heading space).
struct RootPlacement {
  // x, z: horizontal offset from the template root; y: height of the response root above the
  // floor (not relative to the template's height, so a shorter user does not sink the partner).
  Vec3 position_hs = Vec3::Zero();
  // The response root's rotation in the template's heading frame.
  Quat rotation_hs = Quat::Identity();

  // The response's heading minus the template's, wrapped to (-pi, pi].
  double relative_yaw_rad() const noexcept;
  // position_hs with its horizontal offset scaled by spacing_scale (the captured spacing fitted
  // to the user's body, PartnerModel::spacing_scale); the height stays.
  Vec3 spaced_position_hs(double spacing_scale) const noexcept {
    return {position_hs.x() * spacing_scale, position_hs.y(), position_hs.z() * spacing_scale};
  }
};

// The partner's root world transform for a user whose root is at `user_root_position_ws` with
// rotation `user_root_rotation_ws`.
Transform place_root(const RootPlacement& placement, const Vec3& user_root_position_ws,
                     const Quat& user_root_rotation_ws) noexcept;

// The placements of one duet, one per frame. Immutable after build().
class SpatialAlignment {
 public:
  SpatialAlignment() = default;

  // The two clips must have the same number of frames (error otherwise) and at least one frame.
  // Placements relative to the template root's heading frame (heading_frame of joint 0).
  static Result<SpatialAlignment> build(const Clip& template_clip, const Clip& response_clip);
  // Placements relative to the template's body heading frame (body_heading_frame): what a user on
  // any rig is placed against, with their own body_heading_frame.
  static Result<SpatialAlignment> build(const Clip& template_clip, const JointRoles& template_roles,
                                        const Clip& response_clip);

  int frame_count() const noexcept { return static_cast<int>(placements_.size()); }
  // frame in [0, frame_count()).
  const RootPlacement& placement(int frame) const noexcept;
  // At a real frame (clamped to the clip): lerp / slerp between the two nearest frames, as the
  // clips themselves are sampled (Clip::sample).
  RootPlacement placement_at(double frame) const noexcept;
  // The template's heading frame (the one the placements are relative to) in the capture's world,
  // at a real frame (clamped; translation lerped, rotation slerped). The partner's smoothing
  // filters the user's heading relative to it (PartnerParams::smooth_relative_to_template).
  Transform template_heading_at(double frame) const noexcept;

 private:
  std::vector<RootPlacement> placements_;
  std::vector<Transform> template_headings_;  // one per frame
};

}  // namespace duet
