// The clips `duet eval --non-dance` follows (issue 11): motion that no part of the library
// explains, on any rig, which the follower must report lost.
#pragma once

#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/io/motion_file.h"

namespace duet::app {

struct NonDanceClip {
  std::string name;
  LoadedMotion motion;
};

// Each entry: "bandai" (the data folder's Bandai clips: a walk, another style of dance, a wave),
// "none", or a motion file ("clip.bvh", "skel.asf+motion.amc"). No entries: "bandai" when the
// data folder holds it, else none. Errors name the entry and what is wrong.
Result<std::vector<NonDanceClip>> load_non_dance_clips(const std::vector<std::string>& entries,
                                                       const std::string& data_dir);

}  // namespace duet::app
