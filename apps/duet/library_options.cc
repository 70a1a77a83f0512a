#include "library_options.h"

#include <fmt/format.h>

#include "duet/io/motion_argument.h"
#include "duet/live/library_file.h"
#include "number_checks.h"
#include "progress.h"

namespace duet::app {

CLI::Validator motion_word_check() {
  return CLI::Validator(
      [](std::string& word) -> std::string {
        Result<std::vector<std::string>> split = split_motion_argument(word);
        return split ? std::string() : split.error().message;
      },
      "MOTION", "");
}

void add_library_options(CLI::App& app, LibraryArgs& args) {
  app.add_option("--library", args.library,
                 "The duets, from a library file (TOML, docs/file-formats.md), or a directory "
                 "holding one or the pair files (SUBJECT_TRIAL*.bvh, SUBJECT.asf + "
                 "SUBJECT_TRIAL.amc). The salsa library: libraries/cmu-salsa.toml")
      ->check(CLI::ExistingPath);
  app.add_option("--pair", args.pair_files,
                 "A captured duet: the LEADER then the PARTNER, each a BVH file or "
                 "SKELETON.asf+MOTION.amc. Repeat for a library of duets (added after "
                 "--library's); the user can jump between them")
      ->type_name("LEADER PARTNER")
      ->expected(2)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(motion_word_check());
  app.add_option("--data-dir", args.data_dir,
                 "The data directory that ${data} in a library file's paths stands for "
                 "(default: $DUET_DATA_DIR; scripts/get-data.sh prints it)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--role", args.role, "The dancer the user dances: leader or partner")
      ->check(CLI::IsMember({"leader", "partner"}));
  app.add_option("--fps", args.fps,
                 "Frame rate of the pair files, overriding their headers and the library file's "
                 "fps (salsa: 60, which libraries/cmu-salsa.toml sets)")
      ->check(fps_check());
  app.add_option("--scale", args.scale,
                 "Metres per unit of the pair files (default: the library file's scale, else "
                 "known per skeleton convention)")
      ->check(scale_check());
  app.add_flag("--trim", args.trim, "Trim a pair whose two clips differ in length to the shorter");
  app.add_option("--grow-library", args.grow_to_states,
                 "Grow the follower's library to STATES template states with time-warped, noisy "
                 "copies of its takes (scale tests: docs/follower.md \"Beam mode\"); a copy's "
                 "place is reported as the copied take's. Pair it with --beam and --model-cache")
      ->type_name("STATES")
      ->check(CLI::Range(1, 50'000'000));
  app.add_option("--model-cache", args.model_cache,
                 "Read the library's template model and the beam's index from FILE when it was "
                 "written for this library, else build them and write FILE (docs/file-formats.md "
                 "\"Model cache\"); a big library then starts in well under a second")
      ->type_name("FILE");
  // Checked once the whole command line is read, so a mistake exits 2 like any usage error.
  app.parse_complete_callback([&args] {
    if (args.pair_files.size() % 2 != 0) {
      throw CLI::ValidationError(
          "--pair", fmt::format("takes two files, LEADER and PARTNER; got only '{}'",
                                args.pair_files.back()));
    }
    if (args.pair_files.empty() && args.library.empty()) {
      throw CLI::RequiredError("--library FILE or --pair LEADER PARTNER");
    }
  });
}

Result<LibrarySetup> resolve_library(const LibraryArgs& args, const FeatureSpec& features) {
  LibrarySetup setup;
  parse_dancer_role(args.role, setup.options.role);
  setup.options.features = features;
  if (!args.library.empty()) {
    Result<LibrarySpec> spec = read_library(args.library, args.data_dir);
    if (!spec) return spec.error();
    setup.pairs = std::move(spec.value().pairs);
    setup.notes = std::move(spec.value().notes);
    setup.options.load.frame_rate = spec.value().frame_rate;
    setup.options.load.metres_per_unit = spec.value().metres_per_unit;
    setup.options.trim_to_shorter = spec.value().trim_to_shorter;
  }
  for (std::size_t k = 0; k + 1 < args.pair_files.size(); k += 2) {
    PairFiles pair;
    for (std::size_t m = 0; m < 2; ++m) {
      Result<std::vector<std::string>> files = split_motion_argument(args.pair_files[k + m]);
      if (!files) return Error{"--pair: " + files.error().message};
      (m == 0 ? pair.leader : pair.partner) = std::move(files).value();
    }
    setup.pairs.push_back(std::move(pair));
  }
  if (args.fps) setup.options.load.frame_rate = args.fps;
  if (args.scale) setup.options.load.metres_per_unit = args.scale;
  if (args.trim) setup.options.trim_to_shorter = true;
  setup.options.grow_to_states = args.grow_to_states;
  setup.options.model_cache = args.model_cache;
  return setup;
}

std::optional<DuetLibrary> load_library(const LibraryArgs& args, const char* command,
                                        const FeatureSpec& features) {
  Result<LibrarySetup> setup = resolve_library(args, features);
  if (!setup) {
    fmt::print(stderr, "duet {}: {}\n", command, setup.error().message);
    return std::nullopt;
  }
  for (const std::string& note : setup.value().notes) {
    fmt::print(stderr, "duet {}: {}: {}\n", command, args.library, note);
  }
  ProgressBar bar("loading duets");
  Result<DuetLibrary> library = DuetLibrary::load(
      setup.value().pairs, setup.value().options,
      [&](int done, int total, const std::string&) { bar.update(done, total); });
  bar.finish();
  if (!library) {
    fmt::print(stderr, "duet {}: {}\n", command, library.error().message);
    return std::nullopt;
  }
  if (!library.value().model_cache_note().empty()) {
    fmt::print(stderr, "duet {}: {}; built the model and wrote the cache\n", command,
               library.value().model_cache_note());
  }
  return std::move(library).value();
}

}  // namespace duet::app
