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
  // The body's mean direction (unit) from the middle of the feet (ankles and toes, the ankles
  // alone when the roles name no toes) to the head, in the clip's world; meaningful only when
  // `problem` is empty. A standing body's head is above its mid-foot, ahead of its ankles.
  Vec3 mean_up = Vec3::UnitY();
  double span_s = 0.0;  // how long a stretch of the clip the mean covers
  // The floor's normal in the world turned to +Y by `axis` (motion/floor_plane.h: the plane
  // through the lower toe of the sampled frames, drawn towards the mean up where the toes do not
  // spread); meaningful only when `problem` is empty.
  Vec3 floor_up = Vec3::UnitY();
  std::string problem;  // why no axis could be read (no frames, a body lying down, ...)
};

// Reads the up axis from the body: the mean, over up to `max_frames` frames spread over the clip,
// of the unit direction from the middle of the feet to the head joint, snapped to the nearest
// signed axis. A dancer who stands most of the time reads within a few degrees of it; when the mean
// is further than 35 degrees from every axis, or its length (how consistently the body pointed one
// way) is under 0.5, nothing is read and `problem` says so.
UpAxisDetection detect_up_axis(const Clip& clip, const JointRoles& roles, int max_frames = 240);

// A world whose floor is not level: a depth camera pitched down, a pose estimator's camera
// frame, a studio's ground plane set askew. Every bone direction is then off by the tilt, and the
// follower, whose features are directions in the body's heading frame, loses the dance: 3 degrees
// cost nothing, 5 degrees up to 1.5 points, 10 degrees 30 points (clean salsa take, noise, an
// improvisation; docs/skeleton-maps.md "Up axis"). The tilt is read from the floor the toes touch
// (UpAxisDetection::floor_up): within 1.3 degrees of the level over every salsa take, where the
// body's mean feet-to-head direction leans with the dancer (up to 3.4 degrees over a take, 7 over
// the first seconds of a Bandai dance) and with a suit's calibration error in the trunk. Over at
// least kLevelLeastSpanS of motion, a floor further than kLevelFromDeg from level is levelled.
inline constexpr double kLevelFromDeg = 3.0;
inline constexpr double kLevelLeastSpanS = 5.0;
// The turn that levels a world whose up is `mean_up` (already near +Y): the shortest arc from
// `mean_up` to +Y, about a horizontal axis, so headings are kept. Identity when `mean_up` is
// within `from_deg` of +Y, or is not a finite non-zero vector.
Quat levelling_rotation(const Vec3& mean_up, double from_deg = kLevelFromDeg);
// The levelling of the world after `detection`'s axis is turned to +Y (from its floor_up):
// identity when the axis could not be read or the detection covers less than kLevelLeastSpanS.
Quat levelling_rotation(const UpAxisDetection& detection);
// Degrees between `mean_up` and +Y (0 for a zero or non-finite vector).
double tilt_from_vertical_deg(const Vec3& mean_up);

// The levelling of a world with a head and no feet (a three-point recording). Its format says Y
// up, but a camera-based tracker that solves head and hands in a pitched camera's frame tilts it,
// and three points in a 12-degree tilted world were followed within 100 ms on 83 % of frames with
// 9 false jumps a minute (docs/evaluation.md, "Three points levelled from the head's path"). A
// dancer's head travels the room at nearly one height (bouncing by centimetres; dips and hops are
// set aside), so the plane through its positions is parallel to the floor: fit_floor over up to
// `max_frames` frames spread over the clip, drawn towards +Y where the head does not travel. The
// same rules as the body's floor (over at least kLevelLeastSpanS, further than kLevelFromDeg from
// level), and the tilt must be three of the fit's standard errors from level: a head's height also
// changes with the dance (level worlds read up to 3.8 degrees, at 2.6 standard errors).
// The identity otherwise, and when `head` is not a joint of the clip.
Quat head_path_levelling(const Clip& clip, int head, int max_frames = 240);

// Turns the whole world of `clip` by `rotation`: the root joint's rotation and position at every
// frame. The skeleton (rest offsets) is unchanged, so a clip turned by R and then by R^-1 is the
// clip it was.
void turn_world(Clip& clip, const Quat& rotation);
// Turns a Y-up clip into the world of a file that load_motion turned by `file_to_y_up`
// (LoadedMotion::file_to_y_up(): the up axis's turn and any levelling): the inverse turn, nothing
// for the identity. For outputs written back into a file's own world.
void turn_to_file_world(Clip& clip, const Quat& file_to_y_up);

}  // namespace duet
