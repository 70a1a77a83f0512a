#include "library_options.h"

#include <fmt/format.h>

#include "progress.h"

namespace duet::app {

void add_library_options(CLI::App& app, LibraryArgs& args) {
  app.add_option("--pair", args.pair_files,
                 "A captured duet: the LEADER file then the PARTNER file (BVH). Repeat for a "
                 "library of duets; the user can jump between them")
      ->required()
      ->expected(2)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(CLI::ExistingFile);
  app.add_option("--role", args.role, "The dancer the user dances: leader or partner")
      ->check(CLI::IsMember({"leader", "partner"}));
  app.add_option("--fps", args.fps,
                 "Frame rate of the pair files, overriding their headers (salsa: 60)")
      ->check(CLI::PositiveNumber);
  app.add_option("--scale", args.scale,
                 "Metres per unit of the pair files (default: known per skeleton convention)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--trim", args.trim, "Trim a pair whose two clips differ in length to the shorter");
}

std::optional<DuetLibrary> load_library(const LibraryArgs& args, const char* command,
                                        const FeatureSpec& features) {
  LibraryOptions options;
  parse_dancer_role(args.role, options.role);
  options.load.frame_rate = args.fps;
  options.load.metres_per_unit = args.scale;
  options.features = features;
  options.trim_to_shorter = args.trim;
  std::vector<PairFiles> pairs;
  for (std::size_t k = 0; k + 1 < args.pair_files.size(); k += 2) {
    pairs.push_back({args.pair_files[k], args.pair_files[k + 1]});
  }
  ProgressBar bar("loading duets");
  Result<DuetLibrary> library =
      DuetLibrary::load(pairs, options, [&](int done, int total, const std::string&) {
        bar.update(done, total);
      });
  bar.finish();
  if (!library) {
    fmt::print(stderr, "duet {}: {}\n", command, library.error().message);
    return std::nullopt;
  }
  return std::move(library).value();
}

}  // namespace duet::app
