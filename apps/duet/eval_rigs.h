// The rigs `duet eval --rigs` delivers its cases on (issue 10): the library's own, a rig of our own
// with other proportions and rest pose, the real rigs of the data folder, or any motion file's.
#pragma once

#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/eval/runner.h"
#include "duet/live/duet_library.h"

namespace duet::app {

// The names `--rigs` knows besides file paths, in the order "all" expands to.
const std::vector<std::string>& known_eval_rig_names();

// Each entry: "native" (the library's template rig), "proportioned" (make_proportioned_rig of it,
// RigProportions::evaluation_variant), "asf" (cmu-salsa/asf-amc/60.asf), "handshake"
// (cmu-handshake/18_01.bvh), "bandai" (bandai/dataset-1_walk_normal_001.bvh), "all", or a motion
// file ("rig.bvh", "skel.asf+motion.amc") whose skeleton is used. Named data rigs are looked up in
// `data_dir`. Errors name the entry and what is wrong.
Result<std::vector<EvalRig>> load_eval_rigs(const std::vector<std::string>& entries,
                                            const std::string& data_dir,
                                            const DuetLibrary& library);

}  // namespace duet::app
