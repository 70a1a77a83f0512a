// Command-line options that describe a duet library: --library FILE|DIR, --pair (repeated),
// --data-dir, --role, --fps, --scale, --trim, --grow-library, --model-cache.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "duet/live/duet_library.h"

namespace duet::app {

struct LibraryArgs {
  // leader, partner, leader, partner, ...: each "take.bvh" or "skeleton.asf+motion.amc"
  std::vector<std::string> pair_files;
  std::string library;   // --library: a library file, or a directory (library_file.h)
  std::string data_dir;  // --data-dir: what ${data} means in a library file
  std::string role = "leader";
  std::optional<double> fps;
  std::optional<double> scale;
  bool trim = false;
  int grow_to_states = 0;   // --grow-library STATES (LibraryOptions::grow_to_states)
  std::string model_cache;  // --model-cache FILE
};

// Registers the options. The command line must give --library or --pair (else exit 2); each
// --pair takes exactly two motion words (else exit 2, naming the option).
void add_library_options(CLI::App& app, LibraryArgs& args);

// The pairs and load options: the --library file's pairs, then the --pair ones; --fps, --scale
// and --trim override the file's fps, scale and trim. Errors name the file and key.
struct LibrarySetup {
  std::vector<PairFiles> pairs;
  LibraryOptions options;
  std::vector<std::string> notes;  // what a recognised directory guessed
};
Result<LibrarySetup> resolve_library(const LibraryArgs& args, const FeatureSpec& features = {});

// Loads the library with a progress line on stderr. Prints the error and returns nullopt on
// failure.
std::optional<DuetLibrary> load_library(const LibraryArgs& args, const char* command,
                                        const FeatureSpec& features = {});

// A CLI11 check for an option that takes one motion: "take.bvh" or "skeleton.asf+motion.amc"
// (an existing file, or two joined by '+'). After parsing, split the word with
// duet::split_motion_argument() (duet/io/motion_argument.h) and pass the result to load_motion().
CLI::Validator motion_word_check();

}  // namespace duet::app
