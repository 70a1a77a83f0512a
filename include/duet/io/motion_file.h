// One entry point for motion files: a BVH file, or an ASF skeleton plus an AMC motion. Detects
// the skeleton convention (joint roles) and applies its known units, so every clip is in metres.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

struct MotionLoadOptions {
  std::optional<double> frame_rate;       // overrides the file's rate
  std::optional<double> metres_per_unit;  // overrides the convention's known units
  std::optional<SkeletonMap> map;         // a user's map instead of detection
};

struct LoadedMotion {
  Clip clip;             // in metres
  JointRoles roles;      // which joint plays each role
  double metres_per_unit = 1.0;  // the scale that was applied to the file's lengths
  std::string description;       // "a.bvh" or "a.asf + b.amc"
};

// Known units per convention: the DAZ-style salsa BVH are about 0.768 units per metre; CMU
// BVH/ASF units are 0.056444 m (inches / 0.45).
double default_metres_per_unit(const std::string& convention);

// `paths` is {file.bvh} or {skeleton.asf, motion.amc} (in either order).
Result<LoadedMotion> load_motion(const std::vector<std::string>& paths,
                                 const MotionLoadOptions& options = {});

}  // namespace duet
