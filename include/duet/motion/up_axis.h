// Which way is up in a motion file. Duet's world is Y-up (the BVH convention, Unity, three.js),
// but a file exported from 3ds Max, Motive or Blender is often Z-up, and its dancer then lies on
// the floor as far as the features can tell: every frame lost. The up axis is read from the body
// itself (a dancer stands: from the feet to the head is up) and the file's world is turned to
// Y-up on loading; outputs in that file's world are turned back.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "duet/math/types.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

enum class UpAxis : int { kPosY, kNegY, kPosZ, kNegZ, kPosX, kNegX };

std::string_view up_axis_name(UpAxis axis);  // "+Y", "-Z", ...
// Reads "y", "+y", "-z", "Z", ... (case-insensitive); false for anything else.
bool parse_up_axis(std::string_view text, UpAxis& axis);
Vec3 up_axis_vector(UpAxis axis);
// The world rotation that takes `axis` to +Y (about X for the Y and Z axes, about Z for X).
Quat rotation_to_y_up(UpAxis axis);
// The signed axis nearest to `direction` (+Y for a zero vector).
UpAxis nearest_axis(const Vec3& direction);

// Whether `roles` name a head and both ankles within a skeleton of `joints` joints.
bool has_feet_and_head(const JointRoles& roles, int joints);
// From the ankles' midpoint to the head joint, in the space of `positions` (one per joint; the
// roles must pass has_feet_and_head): up, for a body that stands.
Vec3 feet_to_head(std::span<const Vec3> positions, const JointRoles& roles);

struct UpAxisDetection {
  UpAxis axis = UpAxis::kPosY;
  // Angle between the body's mean feet-to-head direction and the axis, degrees (how upright the
  // dancer stood in that world); meaningful only when `problem` is empty.
  double off_axis_deg = 0.0;
  std::string problem;  // why no axis could be read (no frames, a body lying down, ...)
};

// Reads the up axis from the body: the mean, over up to `max_frames` frames spread over the clip,
// of the unit direction from the ankles' midpoint to the head joint, snapped to the nearest signed
// axis. A dancer who stands most of the time reads within a few degrees of it; when the mean is
// further than 35 degrees from every axis, or its length (how consistently the body pointed one
// way) is under 0.5, nothing is read and `problem` says so.
UpAxisDetection detect_up_axis(const Clip& clip, const JointRoles& roles, int max_frames = 240);

// Turns the whole world of `clip` by `rotation`: the root joint's rotation and position at every
// frame. The skeleton (rest offsets) is unchanged, so a clip turned by R and then by R^-1 is the
// clip it was.
void turn_world(Clip& clip, const Quat& rotation);
// Turns a Y-up clip into the world of a file whose up axis is `up`: the inverse of the turn
// load_motion applies (nothing for +Y). For outputs written back into a file's own world.
void turn_to_file_world(Clip& clip, UpAxis up);

}  // namespace duet
