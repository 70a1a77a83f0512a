// Recorded performances for `duet eval --recorded TAKE=FILE` (issue 10): a real capture of one of
// the library's takes danced again, e.g. take 01 on the original CMU ASF rig, scored like the
// synthetic cases (its frame i is the take's moment i / rate), the partner metrics included.
#pragma once

#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/eval/runner.h"
#include "duet/io/motion_file.h"
#include "duet/live/duet_library.h"

namespace duet::app {

// Each entry is "TAKE=FILE": TAKE a take's name in the library (e.g. "01") or its index, FILE a
// motion word ("take.bvh", "skel.asf+motion.amc"), loaded with `load_options` (roles detected,
// units guessed, Y up and levelled as `duet follow` loads its input). Gives one case per entry,
// named "recorded-" + the take's name. Errors name the entry and what is wrong.
Result<std::vector<EvalCase>> load_recorded_cases(const std::vector<std::string>& entries,
                                                  const MotionLoadOptions& load_options,
                                                  const DuetLibrary& library);

}  // namespace duet::app
