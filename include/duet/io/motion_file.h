// One entry point for motion files: a BVH file, or an ASF skeleton plus an AMC motion. Detects
// the skeleton convention (joint roles) and applies its known units, or guesses the units from the
// body's height when no convention says, so every clip is in metres.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "duet/base/result.h"
#include "duet/math/rotation.h"
#include "duet/motion/body_space.h"
#include "duet/motion/clip.h"
#include "duet/motion/role_detection.h"
#include "duet/motion/skeleton_map.h"
#include "duet/motion/up_axis.h"

namespace duet {

struct MotionLoadOptions {
  std::optional<double> frame_rate;       // overrides the file's rate
  std::optional<double> metres_per_unit;  // overrides the convention's known units
  std::optional<SkeletonMap> map;         // a user's map instead of detection
  // When false, a skeleton whose roles cannot all be found still loads (for duet inspect):
  // `roles` then holds -1 for the missing roles and `role_detection.problem` says why.
  bool require_roles = true;
  // The file's up axis (--up); read from the body when not given (motion/up_axis.h). A given
  // axis is taken as exact: the world is not levelled.
  std::optional<UpAxis> up_axis;
  // The levelling turn to apply after the up axis's (a library partner's file shares the
  // leader's world); by default read from the body with the up axis.
  std::optional<Quat> level;
};

// LoadedMotion::up_source when MotionLoadOptions::up_axis gave the axis.
inline constexpr std::string_view kUpAxisGiven = "given (--up)";

struct LoadedMotion {
  Clip clip;             // in metres
  JointRoles roles;      // which joint plays each role
  RoleDetection role_detection;  // how each role was found (notes), or what is missing
  double metres_per_unit = 1.0;  // the scale that was applied to the file's lengths
  // How the units were decided: "convention daz", "ASF file", "guessed from height",
  // "given (--scale)", or "default (metres)" when nothing could tell.
  std::string units_source;
  std::string units_name;     // "metres", "centimetres", ... or "" when given as a number
  std::string units_warning;  // non-empty when the units are doubtful (body height implausible)
  BodyDimensions body;        // in metres; invalid (zeros) when roles are missing
  std::string description;    // "a.bvh" or "a.asf + b.amc"
  // The file's up axis. `clip` is always Y-up: a file with another up axis was turned by
  // rotation_to_y_up(up_axis) on loading, and what is written back into its world (the user's
  // own output, the partner in the user's world) is turned back.
  UpAxis up_axis = UpAxis::kPosY;
  // A tilted world levelled after the up axis's turn (motion/up_axis.h, levelling_rotation); the
  // identity for a level world.
  Quat level = Quat::Identity();
  // The tilt the levelling removed, degrees (0 for a level world).
  double tilt_deg() const { return rad_to_deg(log_map(level).norm()); }
  // The whole turn applied on loading; turn_to_file_world(clip, file_to_y_up()) undoes it.
  Quat file_to_y_up() const { return (level * rotation_to_y_up(up_axis)).normalized(); }
  // How the up axis was decided: "read from the body", kUpAxisGiven, or "assumed (+Y)" when the
  // body could not tell (up_warning then says why).
  std::string up_source;
  std::string up_warning;
};

// Known units per convention: the DAZ-style salsa BVH are about 0.768 units per metre; CMU
// BVH/ASF units are 0.056444 m (inches / 0.45). 1 for conventions with no known units.
double default_metres_per_unit(const std::string& convention);
std::optional<double> known_metres_per_unit(const std::string& convention);

// The units of a skeleton with no known convention, from its body height: among metres,
// centimetres, millimetres, inches and CMU units (0.056444 m), the one that makes the standing
// height (measure_body in file units) closest to 1.7 m (in ratio) within 0.9-2.3 m.
struct UnitGuess {
  double metres_per_unit = 1.0;
  std::string name;     // "centimetres", ...; "metres" when nothing was plausible
  std::string warning;  // why the guess failed, empty when one unit was plausible
};
UnitGuess guess_units_from_height(double height_in_file_units);

// The metres per file unit that load_motion finds, without --scale, in a BVH file of `skeleton`
// (lengths in metres) written at `metres_per_unit`: the convention's known units, else the unit
// guessed from the body's height, else metres.
double metres_per_unit_read_back(const Skeleton& skeleton, double metres_per_unit);

// The metres per unit to write a BVH file of `skeleton` (in metres) in, so that every duet command
// reads it back at its true size with no flags: the first of `preferred` (say, the units of the
// file the motion came from), the convention's known units and metres that reads back as
// written. A BVH has no field for its units: the reader can only infer them, so the writer must
// write what the reader will infer (a salsa skeleton written in metres would read back 1.3x too
// big, a CMU one 18x too small).
double readable_metres_per_unit(const Skeleton& skeleton, double preferred);

// `paths` is {file.bvh} or {skeleton.asf, motion.amc} (in either order).
Result<LoadedMotion> load_motion(const std::vector<std::string>& paths,
                                 const MotionLoadOptions& options = {});

}  // namespace duet
