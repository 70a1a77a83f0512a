// Command-line options that describe a duet library: --pair (repeated), --role, --fps, --scale.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "duet/live/duet_library.h"

namespace duet::app {

struct LibraryArgs {
  std::vector<std::string> pair_files;  // leader, partner, leader, partner, ...
  std::string role = "leader";
  std::optional<double> fps;
  std::optional<double> scale;
  bool trim = false;
};

void add_library_options(CLI::App& app, LibraryArgs& args);
// Loads the library with a progress line on stderr. Prints the error and returns nullopt on
// failure.
std::optional<DuetLibrary> load_library(const LibraryArgs& args, const char* command,
                                        const FeatureSpec& features = {});

}  // namespace duet::app
