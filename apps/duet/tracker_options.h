// Command-line choice of the follower: the jump HMM (default) or a baseline, and its parameters.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>

#include "duet/base/result.h"
#include "duet/features/feature_spec.h"
#include "duet/follow/follow_params.h"
#include "duet/follow/tracker.h"
#include "duet/live/duet_library.h"

namespace duet::app {

struct TrackerArgs {
  std::string kind = "hmm";        // hmm | left-to-right | nearest | dtw | naive
  std::string preset = "default";  // default | paper
  std::optional<float> sigma;      // emission sigma override
  bool fixed_band = false;         // tempo_adaptive = false
  bool beam = false;               // beam mode of the HMM (beam_follower.h)
};

void add_tracker_options(CLI::App& app, TrackerArgs& args);

// The follower's parameters for the library's input points. Three points (a headset and two
// controllers) take no unexplained-jump hold (FollowParams::unexplained_jump_hold_s): they have no
// limb an optical system could hold where it last saw it, and fit the template less closely, so
// the hold delayed true jumps (`improv-library` 2.6 points lower on the handshake rig with the
// arms-forward calibration; docs/evaluation.md, "An arm held where last seen").
FollowParams suited_to_points(FollowParams params, InputPoints points);

// The tracker for `library` (its model, its input points and the beam's jump candidate index).
Result<std::unique_ptr<Tracker>> make_tracker(const TrackerArgs& args, const DuetLibrary& library);

}  // namespace duet::app
