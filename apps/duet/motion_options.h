// Command-line options shared by every subcommand that reads motion files.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "duet/io/motion_file.h"

namespace duet::app {

struct MotionFileOptions {
  std::optional<double> fps;    // --fps: override the file's frame rate
  std::optional<double> scale;  // --scale: metres per file unit
  std::string map_path;         // --map: a skeleton map JSON file
  std::string up;               // --up: the file's up axis ("auto" or empty: read from the body)
};

void add_motion_file_options(CLI::App& app, MotionFileOptions& options,
                             const std::string& prefix = "");
// Turns the options into load options; prints an error and returns false on a bad map file.
bool make_load_options(const MotionFileOptions& options, MotionLoadOptions& load_options);

}  // namespace duet::app
