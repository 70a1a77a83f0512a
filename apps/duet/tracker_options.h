// Command-line choice of the follower: the jump HMM (default) or a baseline, and its parameters.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>

#include "duet/base/result.h"
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

// The tracker for `library`: its model, the parameters for its input points (follow_params_for)
// and the beam's jump candidate index.
Result<std::unique_ptr<Tracker>> make_tracker(const TrackerArgs& args, const DuetLibrary& library);

}  // namespace duet::app
