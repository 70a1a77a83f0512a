// duet improvise (--from TAKE.bvh | --pair LEADER PARTNER [...] --take K) -o PERF.bvh
//                [--truth TRUTH.csv] [--mode improv|play] [perturbations] [--seed N]
// Writes one synthetic performance with its ground truth, to be fed to `duet follow`.
#include <fmt/format.h>

#include <algorithm>
#include <iterator>

#include "commands.h"
#include "duet/eval/performance.h"
#include "duet/io/atomic_write.h"
#include "duet/io/bvh.h"
#include "duet/io/motion_argument.h"
#include "duet/live/duet_library.h"
#include "library_options.h"
#include "number_checks.h"

namespace duet::app {

namespace {

struct ImproviseArgs {
  std::string from;
  std::vector<std::string> pair_files;
  std::string library;
  std::string data_dir;
  int take = -1;
  std::string role = "leader";
  std::optional<double> fps;
  std::optional<double> scale;
  bool across_takes = false;

  std::string output_path;
  std::string truth_path;
  std::string mode = "improv";
  double pause_prob = 1.0;
  double continue_prob = 0.2;
  double segment_min_s = 2.0, segment_max_s = 5.0;
  double duration_s = 0.0;
  double tempo = 1.0;
  std::vector<double> drift;
  double noise_deg = 0.0, noise_cm = 0.0;
  double rate_hz = 0.0;
  double body_scale = 1.0;
  double room_yaw_deg = 0.0;
  std::vector<double> room_offset;
  std::uint64_t seed = 1;
};

constexpr const char* kCommand = "duet improvise";

int usage_error(const std::string& message) {
  fmt::print(stderr, "{}: {}\n", kCommand, message);
  return kExitUsage;
}

int run_improvise(const ImproviseArgs& args) {
  // Where the motion comes from: one file (take 0), or the user's role in pair K of a list (take
  // K, the index `duet follow --pair ...` gives that take when the same pairs are passed).
  const bool from_file = !args.from.empty();
  if (from_file == (!args.pair_files.empty() || !args.library.empty())) {
    return usage_error(
        "give either --from FILE or --library FILE / --pair LEADER PARTNER [...] with --take K");
  }
  if (from_file && (args.take >= 0 || args.across_takes)) {
    return usage_error("--take and --across-takes go with --pair or --library, not --from");
  }
  if (args.pair_files.size() % 2 != 0) {
    return usage_error("--pair takes two files, LEADER and PARTNER; got only '" +
                       args.pair_files.back() + "'");
  }
  // The pairs (a library file's, then --pair's) and their load options (the file's fps).
  std::vector<PairFiles> pair_list;
  MotionLoadOptions load;
  load.frame_rate = args.fps;
  load.metres_per_unit = args.scale;
  if (!from_file) {
    LibraryArgs library_args;
    library_args.pair_files = args.pair_files;
    library_args.library = args.library;
    library_args.data_dir = args.data_dir;
    library_args.fps = args.fps;
    library_args.scale = args.scale;
    Result<LibrarySetup> setup = resolve_library(library_args);
    if (!setup) {
      fmt::print(stderr, "{}: {}\n", kCommand, setup.error().message);
      return kExitFailure;
    }
    pair_list = std::move(setup.value().pairs);
    load = setup.value().options.load;
  }
  const int pairs = static_cast<int>(pair_list.size());
  if (!from_file && (args.take < 0 || args.take >= pairs)) {
    return usage_error(args.take < 0 ? std::string("--pair needs --take K (0-based)")
                                     : fmt::format("--take {}: there are {} pairs (0..{})",
                                                   args.take, pairs, pairs - 1));
  }
  DancerRole role = DancerRole::kLeader;
  parse_dancer_role(args.role, role);
  if (args.drift.size() == 2 && !(args.drift[0] > 0.0 && args.drift[1] > args.drift[0])) {
    return usage_error("--drift LOW HIGH needs 0 < LOW < HIGH");
  }
  if (args.segment_min_s > args.segment_max_s) {
    return usage_error("--segment-min must not exceed --segment-max");
  }
  if (args.mode == "play" && args.across_takes) {
    return usage_error("--across-takes needs --mode improv");
  }

  std::vector<std::vector<std::string>> files;
  std::vector<int> indices;
  if (from_file) {
    files.push_back(split_motion_argument(args.from).value());  // checked by motion_word_check
    indices.push_back(0);
  } else {
    for (int k = 0; k < pairs; ++k) {
      if (k != args.take && !args.across_takes) continue;
      const PairFiles& pair = pair_list[static_cast<std::size_t>(k)];
      files.push_back(role == DancerRole::kLeader ? pair.leader : pair.partner);
      indices.push_back(k);
    }
    // The performed take first.
    const auto it = std::ranges::find(indices, args.take);
    std::iter_swap(files.begin(), files.begin() + (it - indices.begin()));
    std::iter_swap(indices.begin(), it);
  }
  std::vector<LoadedMotion> motions;
  for (const std::vector<std::string>& file : files) {
    Result<LoadedMotion> motion = load_motion(file, load);
    if (!motion) {
      fmt::print(stderr, "{}: {}\n", kCommand, motion.error().message);
      return kExitFailure;
    }
    if (motion.value().clip.frame_count() < 2) {
      fmt::print(stderr, "{}: {}: needs at least 2 frames\n", kCommand,
                 join_motion_argument(file));
      return kExitFailure;
    }
    motions.push_back(std::move(motion).value());
  }
  std::vector<SourceTake> sources;
  for (std::size_t k = 0; k < motions.size(); ++k) {
    sources.push_back({indices[k], &motions[k].clip, motions[k].roles});
  }

  PerformanceRecipe recipe;
  recipe.improvise = args.mode == "improv";
  TempoOptions tempo;
  tempo.factor = args.tempo;
  if (args.drift.size() == 2) {
    tempo.drift_low = args.drift[0];
    tempo.drift_high = args.drift[1];
  }
  recipe.play.tempo = tempo;
  recipe.play.rate_hz = args.rate_hz;
  ImproviseOptions& improv = recipe.improvise_options;
  improv.tempo = tempo;
  improv.rate_hz = args.rate_hz;
  improv.duration_s = args.duration_s;
  improv.segment_min_s = args.segment_min_s;
  improv.segment_max_s = args.segment_max_s;
  improv.continue_prob = args.continue_prob;
  improv.pause_prob = args.pause_prob;
  recipe.body_scale = args.body_scale;
  recipe.room_yaw_rad = deg_to_rad(args.room_yaw_deg);
  if (args.room_offset.size() == 2)
    recipe.room_offset_m = Vec3(args.room_offset[0], 0.0, args.room_offset[1]);
  recipe.noise.rotation_deg = args.noise_deg;
  recipe.noise.position_m = args.noise_cm / 100.0;

  Result<Performance> made = make_performance(sources, recipe, args.seed);
  if (!made) {
    fmt::print(stderr, "{}: {}\n", kCommand, made.error().message);
    return kExitFailure;
  }
  const Performance& performance = made.value();

  // In the source file's units, so `duet follow` reads it back with the same scale as the pairs.
  const BvhWriteOptions units = BvhWriteOptions::in_file_units(
      readable_metres_per_unit(performance.motion.skeleton(), motions[0].metres_per_unit));
  if (Status s = write_bvh(performance.motion, args.output_path, units); !s) {
    fmt::print(stderr, "{}: {}\n", kCommand, s.error().message);
    return kExitFailure;
  }
  int jumps = 0, pause_frames = 0;
  if (!args.truth_path.empty()) {
    std::string csv = "frame,time_s,take,template_frame,in_pause,jump\n";
    for (int f = 0; f < performance.frame_count(); ++f) {
      const TruthFrame& t = performance.truth[static_cast<std::size_t>(f)];
      fmt::format_to(std::back_inserter(csv), "{},{:.6f},{},{:.3f},{},{}\n", f,
                     performance.times_s[static_cast<std::size_t>(f)], t.take, t.template_frame,
                     t.in_pause ? 1 : 0, t.jump ? 1 : 0);
    }
    if (Status s = write_file_atomically(args.truth_path, csv); !s) {
      fmt::print(stderr, "{}: {}\n", kCommand, s.error().message);
      return kExitFailure;
    }
  }
  for (const TruthFrame& t : performance.truth) {
    jumps += t.jump ? 1 : 0;
    pause_frames += t.in_pause ? 1 : 0;
  }
  fmt::print("wrote {}: {} frames at {:g} fps ({:.1f} s), {} jumps, {} pause frames{}\n",
             args.output_path, performance.frame_count(), performance.motion.frame_rate(),
             performance.frame_count() / performance.motion.frame_rate(), jumps, pause_frames,
             args.truth_path.empty() ? "" : "; truth in " + args.truth_path);
  return kExitOk;
}

}  // namespace

Command register_improvise(CLI::App& app) {
  auto args = std::make_shared<ImproviseArgs>();
  auto* source = app.add_option_group("source", "Where the performance comes from");
  source
      ->add_option("--from", args->from,
                   "One take of the user's role (BVH or SKELETON.asf+MOTION.amc); its take index "
                   "is 0")
      ->check(motion_word_check());
  source
      ->add_option("--library", args->library,
                   "The duets as for `duet follow`: a library file or a directory "
                   "(libraries/cmu-salsa.toml). The truth's take is the pair's index in it")
      ->check(CLI::ExistingPath);
  source
      ->add_option("--pair", args->pair_files,
                   "A captured duet: LEADER then PARTNER (BVH or SKELETON.asf+MOTION.amc); repeat "
                   "as for `duet follow`. The truth's take is the index of the pair in the list "
                   "(after --library's)")
      ->type_name("LEADER PARTNER")
      ->expected(2)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(motion_word_check());
  source->add_option("--data-dir", args->data_dir,
                     "What ${data} means in a library file (default: $DUET_DATA_DIR)")
      ->check(CLI::ExistingDirectory);
  source->add_option("--take", args->take, "With --pair/--library: the pair to perform from (0-based)");
  source->add_option("--role", args->role, "With --pair: the dancer the user dances")
      ->check(CLI::IsMember({"leader", "partner"}));
  source
      ->add_option("--fps", args->fps,
                   "Frame rate of the source file(s), overriding the library file's (salsa: 60)")
      ->check(fps_check());
  source->add_option("--scale", args->scale, "Metres per unit of the source file(s)")
      ->check(scale_check());
  source->add_flag("--across-takes", args->across_takes,
                   "With --pair: improvise with segments of every pair's take");

  app.add_option("-o,--output", args->output_path,
                 "The performance (BVH at the performance's rate, in the source's units)")
      ->required();
  app.add_option("--truth", args->truth_path,
                 "Ground truth CSV: frame,time_s,take,template_frame,in_pause,jump");
  app.add_option("--mode", args->mode,
                 "improv (default): segments in another order; play: the whole take")
      ->check(CLI::IsMember({"improv", "play"}));
  app.add_option("--pause-prob", args->pause_prob,
                 "Probability of a 0.3-0.8 s hold before each jump (default 1)")
      ->check(number_between(0.0, 1.0));
  app.add_option("--continue-prob", args->continue_prob,
                 "Probability that a segment goes on into the next one (default 0.2)")
      ->check(number_between(0.0, 1.0));
  app.add_option("--segment-min", args->segment_min_s, "Shortest segment in s (default 2)")
      ->check(number_between(0.1, kMaxDurationS, "s"));
  app.add_option("--segment-max", args->segment_max_s, "Longest segment in s (default 5)")
      ->check(number_between(0.1, kMaxDurationS, "s"));
  app.add_option("--duration", args->duration_s,
                 "Length of an improvised performance in s (default: the take's)")
      ->check(number_between(0.0, kMaxDurationS, "s"));
  app.add_option("--tempo", args->tempo, "Steady tempo factor (1.4 = 40% faster; default 1)")
      ->check(number_between(0.1, 10.0));
  app.add_option("--drift", args->drift, "Drifting tempo between LOW and HIGH, e.g. 0.8 1.3")
      ->expected(2)
      ->check(number_between(0.1, 10.0));
  app.add_option("--noise-deg", args->noise_deg, "Rotation noise, RMS degrees per joint")
      ->check(non_negative_check());
  app.add_option("--noise-cm", args->noise_cm, "Root position noise per axis in cm")
      ->check(non_negative_check());
  app.add_option("--rate", args->rate_hz, "Sensor rate in Hz (default: the take's, e.g. 30)")
      ->check(fps_check());
  app.add_option("--body-scale", args->body_scale, "Body size factor (e.g. 1.15)")
      ->check(number_between(0.1, 10.0));
  app.add_option("--room-yaw", args->room_yaw_deg, "Turn the dancer about the vertical (deg)");
  app.add_option("--room-offset", args->room_offset, "Move the dancer by X Z metres")->expected(2);
  app.add_option("--seed", args->seed, "Seed of every random choice");
  return [args] { return run_improvise(*args); };
}

}  // namespace duet::app
