// --input-points: which points of the user's body the follower sees (issue 12). A three-point
// recording (head and hands) always gives the three-point follower; a full-body input gives it
// with --input-points head,hands, which keeps only the head and the wrists (to test three points
// against full-body truth).
#pragma once

#include <string>

#include "duet/base/result.h"
#include "duet/features/feature_spec.h"
#include "duet/io/motion_file.h"

namespace duet::app {

inline constexpr const char* kInputPointsHelp =
    "Which points of the input the follower sees: full (the whole body) or head,hands (what a "
    "headset and two controllers give). Default: head,hands for a three-point input, else full";

// `option` is "", "full" or "head,hands". With head,hands on a full-body motion, `motion` becomes
// its three points. Errors when the input cannot give what is asked.
Result<InputPoints> choose_input_points(const std::string& option, LoadedMotion& motion);

}  // namespace duet::app
