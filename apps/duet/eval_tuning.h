// `duet eval`'s tuning options: the FollowParams fields a tuning experiment may set, each named
// once in one table (its flag, the field, its help and its check), registered, applied and
// reported from there (docs/evaluation.md, "Running it").
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <vector>

#include "duet/follow/follow_params.h"

namespace duet::app {

class FollowTuning {
 public:
  FollowTuning();

  // Adds every tuning option to `group`.
  void add_options(CLI::Option_group& group);
  // Sets the fields asked for on the command line; the others keep their values in `params`.
  // Applied on top of follow_params_for, so what an option asked for stays whatever the input
  // points are.
  void apply(FollowParams& params) const;

 private:
  std::vector<std::optional<float>> floats_;  // one per row of the float table
  std::optional<int> jump_tolerance_;
  std::optional<int> jump_burst_jumps_;
  std::optional<double> tempo_time_constant_;
  bool fixed_band_ = false;
  bool no_outlier_gate_ = false;
  bool pause_reported_lost_ = false;
};

}  // namespace duet::app
