// duet eval --pair LEADER PARTNER [...] [--takes 0,2] [--cases ...] [--noise-sweep] [--suit-sweep]
//           [--body-sweep]
//           [--trackers ...] [--csv F] [--plots DIR] [--no-partner-metrics] [--partner-csv F]
//           [tuning options]
// Synthetic performances with ground truth from the real takes, followed by the HMM and the
// baselines; prints a table (docs/evaluation.md).
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <optional>
#include <set>

#include "commands.h"
#include "duet/base/parse_number.h"
#include "duet/eval/non_dance.h"
#include "duet/eval/report.h"
#include "duet/eval/runner.h"
#include "duet/io/atomic_write.h"
#include "eval_non_dance.h"
#include "eval_recorded.h"
#include "eval_rigs.h"
#include "eval_tuning.h"
#include "input_points.h"
#include "library_options.h"
#include "motion_options.h"
#include "number_checks.h"
#include "progress.h"
#include "tracker_options.h"

namespace duet::app {

namespace {

struct EvalArgs {
  LibraryArgs library;
  std::vector<std::string> takes;  // indices, FIRST-LAST ranges, or "all"
  std::vector<std::string> cases;
  std::vector<std::string> trackers;
  std::vector<std::string> rigs = {"native"};
  std::vector<std::string> non_dance;  // empty: the Bandai clips when the data folder has them
  std::uint64_t seed = 1;
  std::string csv_path;
  std::string frames_csv_path;
  std::string plots_dir;
  std::string trace_case = "improv-pause";
  bool no_partner_metrics = false;
  bool beam = false;
  bool no_lost_confidence = false;
  bool noise_sweep = false;
  bool suit_sweep = false;
  bool body_sweep = false;
  bool rate_sweep = false;
  bool tempo_sweep = false;
  std::vector<std::string> recorded;  // TAKE=FILE
  MotionFileOptions recorded_motion;
  std::string partner_csv_path;
  CaseSettings settings;
  double noise_cm = 1.0;
  std::string input_points = "full";
  double point_noise_mm = 5.0;
  double point_noise_deg = 1.0;
  std::vector<double> device_offsets_cm;  // eyes forward, eyes up, grip; empty: at the joints
  std::vector<double> taken_out_cm;       // what the follower takes out; empty: nothing
  double tell_head_height = 0.0;  // the performer's head height standing times this; 0: not told
  bool tell_arms_forward = false;             // the performer's wrists with arms held forward
  std::vector<double> arms_forward_error_cm;  // OUT,UP,FORWARD added to each wrist; empty: none
  // Tuning of the "hmm" tracker (FollowParams fields); unset keeps the follower's defaults.
  FollowTuning tuning;
  std::optional<int> dtw_back, dtw_ahead;
  // Feature weights (FeatureSpec); unset keeps the defaults.
  std::optional<double> posture_weight, head_hands_posture_weight, root_velocity_weight,
      effector_speed_weight, velocity_window;
};

constexpr const char* kCommand = "eval";

int usage_error(const std::string& message) {
  fmt::print(stderr, "duet eval: {}\n", message);
  return kExitUsage;
}

// Case names, plus the group "tempo" (tempo-slow, tempo-fast) and "all".
bool select_cases(const std::vector<std::string>& names, const std::vector<EvalCase>& standard,
                  std::vector<EvalCase>& selected, std::string& error) {
  std::set<std::string> wanted;
  for (const std::string& name : names) {
    if (name == "all") {
      for (const EvalCase& c : standard) wanted.insert(c.name);
    } else if (name == "tempo") {
      wanted.insert("tempo-slow");
      wanted.insert("tempo-fast");
    } else if (std::ranges::none_of(standard, [&](const EvalCase& c) { return c.name == name; })) {
      std::string known;
      for (const EvalCase& c : standard) known += (known.empty() ? "" : ", ") + c.name;
      error = "unknown case '" + name + "' (known: " + known + ", tempo, all)";
      return false;
    } else {
      wanted.insert(name);
    }
  }
  for (const EvalCase& c : standard) {  // report order
    if (wanted.contains(c.name)) selected.push_back(c);
  }
  return true;
}

// The gnuplot program on PATH, or empty.
std::string find_gnuplot() {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  std::string dirs = path;
  std::size_t begin = 0;
  while (begin <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', begin), dirs.size());
    const std::string dir = dirs.substr(begin, end - begin);
    const std::string candidate = (dir.empty() ? "." : dir) + "/gnuplot";
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
    begin = end + 1;
  }
  return {};
}

std::string shell_quote(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// --takes: indices, FIRST-LAST ranges and "all" into take indices, each once, in the order given;
// an error that names the bad item.
Result<std::vector<int>> parse_takes(const std::vector<std::string>& items, int pair_count) {
  const auto bad = [&](const std::string& item, const std::string& why) -> Error {
    return Error{fmt::format("--takes {}: {}", item, why)};
  };
  const auto index = [&](const std::string& item, std::string_view text) -> Result<int> {
    const std::optional<int> parsed = parse_number<int>(text);
    if (!parsed) return bad(item, "expected a take index, FIRST-LAST or all");
    const int k = *parsed;
    if (k < 0 || k >= pair_count) {
      return bad(item, fmt::format("the library has {} pair{} (takes 0..{})", pair_count,
                                   pair_count == 1 ? "" : "s", pair_count - 1));
    }
    return k;
  };
  std::vector<int> takes;
  const auto add = [&](int k) {
    if (std::ranges::find(takes, k) == takes.end()) takes.push_back(k);
  };
  for (const std::string& item : items) {
    if (item == "all") {
      for (int k = 0; k < pair_count; ++k) add(k);
      continue;
    }
    const std::size_t dash = item.find('-', 1);
    if (dash == std::string::npos) {
      Result<int> k = index(item, item);
      if (!k) return k.error();
      add(k.value());
      continue;
    }
    Result<int> first = index(item, std::string_view(item).substr(0, dash));
    if (!first) return first.error();
    Result<int> last = index(item, std::string_view(item).substr(dash + 1));
    if (!last) return last.error();
    if (last.value() < first.value()) return bad(item, "the range ends before it begins");
    for (int k = first.value(); k <= last.value(); ++k) add(k);
  }
  return takes;
}

int write_plots(const EvalReport& report, const std::string& dir, const std::string& gnuplot) {
  const std::string quiet = " >/dev/null 2>&1";
  const bool cairo =
      std::system((shell_quote(gnuplot) + " -e 'set terminal pngcairo'" + quiet).c_str()) == 0;
  for (const PlotFile& file : make_eval_plots(report, cairo ? "pngcairo" : "png")) {
    if (Status s =
            write_file_atomically((std::filesystem::path(dir) / file.name).string(), file.content);
        !s) {
      fmt::print(stderr, "duet eval: {}\n", s.error().message);
      return kExitFailure;
    }
  }
  const std::string command =
      "cd " + shell_quote(dir) + " && " + shell_quote(gnuplot) + " plots.gp 2>&1";
  if (std::system(command.c_str()) != 0) {
    fmt::print(stderr, "duet eval: gnuplot failed on {}/plots.gp\n", dir);
    return kExitFailure;
  }
  fmt::print("plots: {}/accuracy.png{}\n", dir,
             report.traces.empty() ? "" : fmt::format(", {}/trace.png", dir));
  return kExitOk;
}

int run_eval(EvalArgs& args) {
  // Everything that can be checked before loading the library.
  Result<LibrarySetup> setup = resolve_library(args.library);  // the pair count, from a file too
  if (!setup) {
    fmt::print(stderr, "duet {}: {}\n", kCommand, setup.error().message);
    return kExitFailure;
  }
  const int pair_count = static_cast<int>(setup.value().pairs.size());
  args.settings.noise_position_m = args.noise_cm / 100.0;
  const std::vector<EvalCase> standard = standard_cases(args.settings);
  EvalOptions options;
  std::string error;
  // A sweep or --recorded alone runs only those; with --cases, after them.
  if (args.cases.empty() && !args.noise_sweep && !args.suit_sweep && !args.body_sweep &&
      !args.rate_sweep && !args.tempo_sweep && args.recorded.empty()) {
    args.cases = {"all"};
  }
  if (!select_cases(args.cases, standard, options.cases, error)) return usage_error(error);
  if (args.noise_sweep) std::ranges::move(noise_sweep_cases(), std::back_inserter(options.cases));
  if (args.suit_sweep) {
    std::ranges::move(suit_sweep_cases(args.settings), std::back_inserter(options.cases));
  }
  if (args.body_sweep) {
    std::ranges::move(body_sweep_cases(args.settings), std::back_inserter(options.cases));
  }
  if (args.rate_sweep) {
    std::ranges::move(rate_sweep_cases(args.settings), std::back_inserter(options.cases));
  }
  if (args.tempo_sweep) {
    std::ranges::move(tempo_sweep_cases(args.settings), std::back_inserter(options.cases));
  }
  if (args.trackers.empty()) {
    options.trackers = all_tracker_kinds();
  } else {
    for (const std::string& name : args.trackers) {
      TrackerKind kind;
      if (!parse_tracker_kind(name, kind)) {
        return usage_error("unknown tracker '" + name +
                           "' (known: hmm, hmm-paper, left-to-right, nearest, online-dtw, "
                           "naive-hmm)");
      }
      options.trackers.push_back(kind);
    }
  }
  Result<std::vector<int>> take_list = parse_takes(args.takes, pair_count);
  if (!take_list) return usage_error(take_list.error().message);
  if (take_list.value().empty()) {  // the first, middle and last take
    for (const int k : {0, (pair_count - 1) / 2, pair_count - 1}) {
      if (std::ranges::find(take_list.value(), k) == take_list.value().end()) {
        take_list.value().push_back(k);
      }
    }
  }
  if (std::ranges::none_of(standard,
                           [&](const EvalCase& c) { return c.name == args.trace_case; })) {
    return usage_error("--trace-case: unknown case '" + args.trace_case + "'");
  }
  if (args.no_partner_metrics && !args.partner_csv_path.empty()) {
    return usage_error("--partner-csv needs the partner metrics (leave out --no-partner-metrics)");
  }
  options.partner_metrics = !args.no_partner_metrics;
  options.beam = args.beam;
  options.lost_confidence = !args.no_lost_confidence;
  options.takes = take_list.value();
  options.seed = args.seed;
  options.trace_case = args.plots_dir.empty() ? "" : args.trace_case;
  options.keep_frames = !args.frames_csv_path.empty();

  if (args.dtw_back) options.dtw.window_back = *args.dtw_back;
  if (args.dtw_ahead) options.dtw.window_ahead = *args.dtw_ahead;

  FeatureSpec features;
  if (args.posture_weight) features.posture_weight = *args.posture_weight;
  if (args.head_hands_posture_weight) {
    features.head_hands_posture_weight = *args.head_hands_posture_weight;
  }
  if (args.root_velocity_weight) features.root_velocity_weight = *args.root_velocity_weight;
  if (args.effector_speed_weight) features.effector_speed_weight = *args.effector_speed_weight;
  if (args.velocity_window) features.velocity_window_s = *args.velocity_window;
  if (!parse_input_points(args.input_points, features.input_points)) {
    return usage_error("--input-points: '" + args.input_points +
                       "' is neither full nor head,hands");
  }
  if ((!args.device_offsets_cm.empty() || !args.taken_out_cm.empty()) &&
      features.input_points != InputPoints::kHeadHands) {
    return usage_error(std::string(args.device_offsets_cm.empty() ? "--taken-out-offsets-cm"
                                                                  : "--device-offsets-cm") +
                       ": applies to three points (--input-points head,hands)");
  }
  if (args.tell_head_height > 0.0 && features.input_points != InputPoints::kHeadHands) {
    return usage_error(
        "--tell-head-height: applies to three points (--input-points head,hands); the full body's "
        "size is its skeleton's");
  }
  if ((args.tell_arms_forward || !args.arms_forward_error_cm.empty()) &&
      features.input_points != InputPoints::kHeadHands) {
    return usage_error(
        "--tell-arms-forward: applies to three points (--input-points head,hands); the full "
        "body's features are directions between its joints");
  }
  if (!args.arms_forward_error_cm.empty() && !args.tell_arms_forward) {
    return usage_error("--arms-forward-error-cm: needs --tell-arms-forward");
  }
  // As `duet follow` and `duet serve` make the follower for these input points; what a tuning
  // option asked for stays.
  FollowParams& hmm = options.hmm;
  hmm = follow_params_for(features.input_points, hmm);
  args.tuning.apply(hmm);
  if (Status s = hmm.validate(1); !s) return usage_error(s.error().message);

  std::string gnuplot;
  if (!args.plots_dir.empty()) {
    gnuplot = find_gnuplot();
    if (gnuplot.empty()) {
      fmt::print(stderr,
                 "duet eval: --plots needs gnuplot, which is not on PATH (install it, e.g. "
                 "`apt-get install gnuplot-nox`, or leave out --plots)\n");
      return kExitFailure;
    }
    std::error_code ec;
    std::filesystem::create_directories(args.plots_dir, ec);
    if (ec) {
      fmt::print(stderr, "duet eval: cannot create the plot directory {}: {}\n", args.plots_dir,
                 ec.message());
      return kExitFailure;
    }
  }

  // The libraries: the user's role, and role=partner for the partner-role case.
  std::optional<DuetLibrary> library = load_library(args.library, kCommand, features);
  if (!library) return kExitFailure;
  const bool need_partner =
      std::ranges::any_of(options.cases, [](const EvalCase& c) { return c.partner_role; });
  std::optional<DuetLibrary> partner_library;
  const DuetLibrary* partner = nullptr;
  if (need_partner) {
    if (args.library.role == "partner") {
      partner = &*library;
    } else {
      LibraryArgs partner_args = args.library;
      partner_args.role = "partner";
      partner_args.model_cache.clear();  // the cache holds the leader's model
      partner_library = load_library(partner_args, kCommand, features);
      if (!partner_library) return kExitFailure;
      partner = &*partner_library;
    }
  }

  // Every case on every rig asked for (the library's own first).
  std::string data_dir = args.library.data_dir;
  if (data_dir.empty() && std::getenv("DUET_DATA_DIR") != nullptr) {
    data_dir = std::getenv("DUET_DATA_DIR");
  }
  // Recorded performances after the chosen cases, loaded before the long run.
  MotionLoadOptions recorded_load;
  if (!make_load_options(args.recorded_motion, recorded_load)) return kExitFailure;
  Result<std::vector<EvalCase>> recorded =
      load_recorded_cases(args.recorded, recorded_load, *library);
  if (!recorded) {
    fmt::print(stderr, "duet eval: {}\n", recorded.error().message);
    return kExitFailure;
  }
  std::ranges::move(recorded.value(), std::back_inserter(options.cases));
  Result<std::vector<EvalRig>> rigs = load_eval_rigs(args.rigs, data_dir, *library);
  if (!rigs) {
    fmt::print(stderr, "duet eval: {}\n", rigs.error().message);
    return kExitFailure;
  }
  options.cases = cases_on_rigs(options.cases, rigs.value());
  // Loaded before the long run, so a wrong file fails at once.
  Result<std::vector<NonDanceClip>> non_dance = load_non_dance_clips(args.non_dance, data_dir);
  if (!non_dance) {
    fmt::print(stderr, "duet eval: {}\n", non_dance.error().message);
    return kExitFailure;
  }
  // Three points: every case's performance is delivered as a headset's head and hands with the
  // headset's tracking noise. A suit's per-joint noise is no headset's: the noisy cases get twice
  // the point noise instead.
  if (features.input_points == InputPoints::kHeadHands) {
    for (EvalCase& eval_case : options.cases) {
      const double factor = eval_case.recipe.noise.active() ? 2.0 : 1.0;
      eval_case.recipe.noise = SensorNoiseOptions{};
      eval_case.recipe.head_hands = true;
      eval_case.recipe.point_noise.position_m = factor * args.point_noise_mm / 1000.0;
      eval_case.recipe.point_noise.rotation_deg = factor * args.point_noise_deg;
      eval_case.recipe.point_noise.offsets = device_offsets_from_cm(args.device_offsets_cm);
      eval_case.recipe.point_noise.taken_out = device_offsets_from_cm(args.taken_out_cm);
      eval_case.recipe.told_head_height_factor = args.tell_head_height;
      eval_case.recipe.tell_arms_forward = args.tell_arms_forward;
      if (!args.arms_forward_error_cm.empty()) {
        // Centimetres of a 1.7 m body's head height (1.58 m) in head heights.
        constexpr double kCmPerHeadHeight = 158.0;
        eval_case.recipe.told_arms_forward_error =
            Vec3(args.arms_forward_error_cm[0], args.arms_forward_error_cm[1],
                 args.arms_forward_error_cm[2]) /
            kCmPerHeadHeight;
      }
    }
  }

  ProgressBar bar("evaluating");
  Result<EvalReport> report = run_evaluation(
      *library, partner, options,
      [&](long long done, long long total, const std::string&) { bar.update(done, total); });
  bar.finish();
  if (!report) {
    fmt::print(stderr, "duet eval: {}\n", report.error().message);
    return kExitFailure;
  }

  std::string takes;
  for (const int k : options.takes) {
    takes += fmt::format("{}{} ({})", takes.empty() ? "" : ", ", k,
                         library->takes()[static_cast<std::size_t>(k)].name);
  }
  fmt::print(
      "library: {} takes, {} states at {:g} fps, user role {}; performances from takes {}; seed "
      "{}\nhmm: self {} next {} skip {} leave {} pause_stay {} sigma {} pause_distance {} "
      "lost_distance {} velocity_cap {} limb_outlier {} x (floor {}) tempo {} jump_hold {} s "
      "jump_tolerance {} jump_settle {} s "
      "(mass {}, advance {} s) noisy_jump_hold {} s unexplained_jump_hold {} s (over {} x noise, "
      "after {} s followed) jump_old_place_mass {} jump_alike_distance {}\n"
      "noise-scaled: pause_noise_factor {} lost_residual {} lost_noise_factor {} "
      "lost_residual_factor {} lost_confirm {} s found_confirm {} x lost (at most {} s) "
      "lost_velocity_cap {}/dim{} held_place_lost {} s (reach {} s) found_still_spell {} s (reach "
      "{} s) "
      "missing_lost {} s "
      "emission_noise_factor {} "
      "emission_noise_allowance {} noise_filter_density {} noise_filter_allowance {}\n\n",
      library->takes().size(), library->model().num_states(), library->frame_rate(),
      args.library.role, takes, options.seed, hmm.self_prob, hmm.next_prob, hmm.skip_prob,
      hmm.leave_prob, hmm.pause_stay_prob, hmm.emission_sigma, hmm.pause_distance_per_dim,
      hmm.lost_distance_per_dim, hmm.velocity_distance_cap, hmm.limb_outlier_ratio,
      hmm.limb_outlier_floor,
      hmm.tempo_adaptive
          ? fmt::format("adaptive ({:g} s; windows of {:g} s under {:g} x the template's "
                        "tempo a hold, untaught for up to {:g} s)",
                        hmm.tempo_time_constant_s, hmm.tempo_hold_window_s, hmm.tempo_hold_advance,
                        hmm.tempo_hold_max_s)
          : "fixed",
      hmm.jump_hold_s, hmm.jump_tolerance_frames, hmm.jump_settle_s, hmm.jump_settle_mass,
      hmm.jump_settle_advance_s, hmm.noisy_jump_hold_s, hmm.unexplained_jump_hold_s,
      hmm.unexplained_jump_ratio, hmm.unexplained_jump_hold_after_s, hmm.jump_old_place_mass,
      hmm.jump_alike_distance_per_dim, hmm.pause_noise_factor, hmm.lost_residual_per_dim,
      hmm.lost_noise_factor, hmm.lost_residual_factor, hmm.lost_confirm_s,
      hmm.found_confirm_per_lost_s, hmm.found_confirm_max_s, hmm.lost_velocity_cap_per_dim,
      hmm.pause_reported_lost ? " pause_reported_lost" : "", hmm.held_place_lost_s,
      hmm.held_place_reach_s, hmm.found_still_spell_s, hmm.found_still_reach_s, hmm.missing_lost_s,
      hmm.emission_noise_factor, hmm.emission_noise_allowance, hmm.noise_filter_density,
      hmm.noise_filter_allowance);
  fmt::print("{}", format_eval_table(report.value()));
  if (!non_dance.value().empty()) {
    fmt::print("\nnon-dance input (motion no part of the library explains; hmm, {}): lost\n",
               options.beam ? "beam mode" : "exact step");
    // Each clip as it is and, when shorter, looped to half a minute: the posture offset has time
    // to learn from a long one (docs/evaluation.md, "Non-dance input for half a minute"). The
    // follower is the cases' hmm, in beam mode under --beam.
    const auto report_lost = [&](const LoadedMotion& motion, const std::string& name) {
      Result<std::unique_ptr<Tracker>> tracker = make_eval_tracker(
          TrackerKind::kHmm, library->model(), options, library->candidate_index());
      if (!tracker) {
        fmt::print(stderr, "duet eval: {}\n", tracker.error().message);
        return false;
      }
      Result<NonDanceResult> result =
          follow_non_dance(*library, motion, name, std::move(tracker).value());
      if (!result) {
        fmt::print(stderr, "duet eval: --non-dance {}\n", result.error().message);
        return false;
      }
      fmt::print("  {:<18} {:6.1f}% of {} frames\n", name, 100.0 * result.value().lost_fraction(),
                 result.value().frames);
      return true;
    };
    constexpr double kLongNonDanceS = 30.0;
    for (const NonDanceClip& clip : non_dance.value()) {
      if (!report_lost(clip.motion, clip.name)) return kExitFailure;
      if (clip.motion.clip.duration() >= kLongNonDanceS) continue;
      LoadedMotion looped = clip.motion;
      looped.clip = looped_clip(clip.motion.clip, kLongNonDanceS);
      if (!report_lost(looped, clip.name + " looped")) return kExitFailure;
    }
  }
  std::fflush(stdout);

  if (!args.csv_path.empty()) {
    if (Status s = write_file_atomically(args.csv_path, format_eval_csv(report.value())); !s) {
      fmt::print(stderr, "duet eval: {}\n", s.error().message);
      return kExitFailure;
    }
  }
  if (!args.frames_csv_path.empty()) {
    if (Status s = write_file_atomically(args.frames_csv_path, format_frames_csv(report.value()));
        !s) {
      fmt::print(stderr, "duet eval: {}\n", s.error().message);
      return kExitFailure;
    }
  }
  if (!args.partner_csv_path.empty()) {
    if (Status s = write_file_atomically(args.partner_csv_path, format_partner_csv(report.value()));
        !s) {
      fmt::print(stderr, "duet eval: {}\n", s.error().message);
      return kExitFailure;
    }
  }
  if (!args.plots_dir.empty()) return write_plots(report.value(), args.plots_dir, gnuplot);
  return kExitOk;
}

}  // namespace

Command register_eval(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  add_library_options(app, args->library);
  app.add_option("--takes", args->takes,
                 "Takes to perform from, as indices of the library's pairs (the --pair list "
                 "after the library's): e.g. 0,2, a range 0-13, or all (default: the first, "
                 "middle and last)")
      ->delimiter(',');
  app.add_option(
         "--rigs", args->rigs,
         "Rigs to deliver every case on, comma-separated (default native): native (the "
         "library's), proportioned (our own: other proportions and rest pose), asf "
         "(cmu-salsa 60.asf), handshake (cmu-handshake 18_01.bvh), bandai (a third-party "
         "rig), game-avatar, depth-camera, inertial-suit (rigs of another build: "
         "docs/retarget.md), all, or a motion file whose skeleton to use. A case on another rig is "
         "reported as CASE@RIG: the same performance, its sensor errors included, "
         "retargeted (docs/retarget.md)")
      ->delimiter(',');
  app.add_option("--non-dance", args->non_dance,
                 "Motion no part of the library explains, comma-separated, followed after the "
                 "cases and reported as the share of frames lost (issue 11: near 100%): bandai "
                 "(the data folder's walk, dance and wave on a third-party rig), none, or motion "
                 "files (default: bandai when the data folder has it). A clip shorter than 30 s "
                 "is also followed looped to 30 s, reported as NAME looped")
      ->delimiter(',');
  app.add_option("--cases", args->cases,
                 "Cases to run, comma-separated (default all): clean, tempo-slow, tempo-fast (or "
                 "tempo), drift, improv, improv-pause, improv-library, noise, 30hz-noisy, "
                 "late-frames, body-size, room-place, partner-role, improv-30hz-noisy, harsh (30 "
                 "Hz, 4 deg per axis + 1 cm noise, 3% repeated frames, a 1.1x body), 120hz-noisy "
                 "(a 120 Hz sensor with the noise), 240hz-slow (a 240 Hz sensor with the noise, "
                 "the dancer at 0.7x), dropouts (the noise, and the sensor loses the dancer for "
                 "0.3-1 s every 8 s), stalls (the noise, and the sensor holds its last pose for "
                 "0.3-2 s every 8 s), suit-drift (an inertial suit: the noise, and every joint off "
                 "by a calibration error and a slow drift), tilted (the noise in a tilted world, "
                 "as a camera pitched down sees it), occluded (the noise, and one arm held where "
                 "last seen for 0.3-1.5 s every 6 s, as an optical system does when the partner "
                 "hides its markers), glitches (the noise, and one joint turned 30-90 deg for 1-3 "
                 "frames every 2 s, as a marker swap or a flipped limb; three points: also a "
                 "controller reported 10-40 cm off)")
      ->delimiter(',');
  app.add_flag("--noise-sweep", args->noise_sweep,
               "Also run noise-sweep-0 ... noise-sweep-5: improv-pause with 0 to 5 degrees of "
               "rotation noise per axis (+1 cm root noise above 0); alone (without --cases) "
               "only these");
  app.add_flag("--suit-sweep", args->suit_sweep,
               "Also run suit-sweep-0, -2, ... -10: an inertial suit (suit-drift) with 0 to 10 "
               "degrees of calibration error and as much drift per joint, with the noise; "
               "alone (without --cases) only these");
  app.add_flag("--body-sweep", args->body_sweep,
               "Also run body-sweep-80, -90, ... -120: improv-pause with the noise, danced by a "
               "body 0.8x to 1.2x the template dancer's; alone (without --cases) only these");
  app.add_flag("--rate-sweep", args->rate_sweep,
               "Also run rate-sweep-20, -25, -30, -50, -60, -72, -90, -120, -240: improv-pause "
               "with the noise from a sensor at that rate (a phone's pose estimator, video, VR "
               "headsets, inertial suits); alone (without --cases) only these");
  app.add_flag("--tempo-sweep", args->tempo_sweep,
               "Also run tempo-sweep-50, -60, -70, -85, -100, -120, -140, -160: improv-pause "
               "with the noise danced at 0.5x to 1.6x the capture's tempo (a learner at half "
               "tempo to a dancer well ahead); alone (without --cases) only these");
  app.add_option("--recorded", args->recorded,
                 "A recording of one of the library's takes danced again, scored like the cases "
                 "(its frame i is the take's moment i / rate), as TAKE=FILE: TAKE a take's name "
                 "or index, FILE a motion file (e.g. 01=60.asf+60_01.amc, the CMU original of take "
                 "01). Reported as recorded-TAKE; repeatable or comma-separated; alone (without "
                 "--cases) only these. --recorded-fps, --recorded-scale, --recorded-map and "
                 "--recorded-up read the file as --input does for `duet follow`")
      ->delimiter(',');
  add_motion_file_options(app, args->recorded_motion, "recorded-");
  app.add_option("--trackers", args->trackers,
                 "Followers, comma-separated (default all): hmm, hmm-paper, left-to-right, "
                 "nearest, online-dtw, naive-hmm (O(M^2), run on the first take alone)")
      ->delimiter(',');
  app.add_option("--input-points", args->input_points,
                 "full, or head,hands: deliver every case as three points (a headset and two "
                 "controllers, with --point-noise-mm and --point-noise-deg of tracking noise, "
                 "twice that on the noisy cases instead of their per-joint noise) and follow with "
                 "the three-point follower")
      ->check(input_points_choice(true));
  app.add_option("--point-noise-mm", args->point_noise_mm,
                 "Three points: position noise per axis of each point, mm (default 5)")
      ->check(number_between(0.0, 100.0, "point noise"));
  app.add_option("--point-noise-deg", args->point_noise_deg,
                 "Three points: orientation noise of each point, RMS degrees (default 1)")
      ->check(number_between(0.0, 45.0, "point noise"));
  add_device_offsets_option(app, args->device_offsets_cm,
                            "The performance's points are put there (e.g. 6,6,7; default: at the "
                            "joints); the partner metrics still score the real wrists");
  add_offsets_cm_option(app, "--taken-out-offsets-cm", args->taken_out_cm,
                        "Three points: the device offsets the follower is told and takes out "
                        "after the sensor noise, FORWARD,UP,GRIP in cm as duet follow's and duet "
                        "serve's --device-offsets-cm (default: none). With --device-offsets-cm, "
                        "how a wrong calibration costs");
  app.add_option("--tell-head-height", args->tell_head_height,
                 "Three points: tell the follower each performer's head height standing (the "
                 "highest the head holds for half a second over the performance) times FACTOR (1: "
                 "exactly, 1.05: 5 % "
                 "high), as duet follow's and duet serve's --head-height would (default: not "
                 "told; the unit is then the highest the head has held so far)")
      ->option_text("FACTOR")
      ->check(number_between(0.5, 2.0, "factor"));
  app.add_flag("--tell-arms-forward", args->tell_arms_forward,
               "Three points: tell the follower where each performer's wrists are with both arms "
               "held straight forward (from its rig: shoulders plus the arm's length), as duet "
               "follow's and duet serve's --calibration would (default: not told; the hands are "
               "then taken where they come)");
  app.add_option("--arms-forward-error-cm", args->arms_forward_error_cm,
                 "With --tell-arms-forward: move each told wrist OUT,UP,FORWARD centimetres (of a "
                 "1.58 m head height), a calibration pose held wider, higher or further")
      ->delimiter(',')
      ->expected(3)
      ->option_text("OUT,UP,FORWARD")
      ->check(CLI::Range(-30.0, 30.0));
  app.add_flag("--beam", args->beam,
               "Run the hmm and hmm-paper trackers in beam mode (docs/follower.md "
               "\"Beam mode\"; the partner metrics keep the exact step)");
  app.add_option("--seed", args->seed, "Seed of every random choice (same seed, same numbers)");
  app.add_option("--csv", args->csv_path, "Write the metrics per case, tracker and take as CSV");
  app.add_option(
      "--frames-csv", args->frames_csv_path,
      "Write every scored frame (case, tracker, take, error, confidence, window mass, "
      "best distance, sensor noise, lost, the tracker's own confidence, the rig's "
      "posture offset and its seconds learnt) as CSV, e.g. for "
      "scripts/fit_confidence_calibration.py and scripts/fit_young_offset_confidence.py");
  app.add_flag("--no-lost-confidence", args->no_lost_confidence,
               "Report a lost frame's confidence as it is before the lost frames' calibration "
               "(the input of scripts/fit_lost_confidence.py; docs/follower.md)");
  app.add_option("--plots", args->plots_dir,
                 "Write PNG plots (needs gnuplot) into this directory: accuracy.png, trace.png, "
                 "reliability.png (confidence against the share within 100 ms, per case)");
  app.add_flag("--no-partner-metrics", args->no_partner_metrics,
               "Skip the partner metrics (by default every case x take also runs the live loop "
               "with the hmm tracker per configuration of the corrections and scores the "
               "synthesized partner: joint error, hand-relation error, foot slip, angular speed "
               "after jumps, us/frame; docs/evaluation.md)");
  app.add_option("--partner-csv", args->partner_csv_path,
                 "Write the partner metrics per case, corrections and take as CSV");
  app.add_option("--trace-case", args->trace_case,
                 "Case whose per-frame estimates trace.png shows (default improv-pause)");

  auto* cases = app.add_option_group("case magnitudes");
  cases
      ->add_option("--noise-deg", args->settings.noise_rotation_deg,
                   "Rotation noise, RMS angle per joint per frame (default 3)")
      ->check(non_negative_check());
  cases->add_option("--noise-cm", args->noise_cm, "Root position noise per axis (default 1)")
      ->check(non_negative_check());
  cases
      ->add_option("--low-rate", args->settings.low_rate_hz,
                   "Sensor rate of the 30hz cases (default 30)")
      ->check(fps_check());
  cases
      ->add_option("--body-scale", args->settings.body_scale,
                   "Body size of the body-size case against the template dancer's, on every rig "
                   "(default 1.15)")
      ->check(number_between(0.1, 10.0));
  cases
      ->add_option("--suit-bias-deg", args->settings.suit_bias_deg,
                   "Calibration error per joint of the suit-drift case, RMS degrees (default 5)")
      ->check(number_between(0.0, 45.0));
  cases
      ->add_option("--suit-drift-deg", args->settings.suit_drift_deg,
                   "Slow drift per joint of the suit-drift case, RMS degrees (default 5)")
      ->check(number_between(0.0, 45.0));
  cases
      ->add_option("--tilt-deg", args->settings.tilt_deg,
                   "How far the tilted case's world is tilted, degrees (default 12)")
      ->check(number_between(0.0, 30.0));
  cases
      ->add_option("--improv-duration", args->settings.improvise_duration_s,
                   "Length of the improvised performances in s (default: the take's length)")
      ->check(number_between(0.0, kMaxDurationS, "s"));

  auto* tuning = app.add_option_group(
      "tuning (FollowParams of the hmm trackers; FeatureSpec weights feed every tracker)");
  args->tuning.add_options(*tuning);
  tuning->add_option("--dtw-back", args->dtw_back, "online DTW window behind the estimate")
      ->check(non_negative_check());
  tuning->add_option("--dtw-ahead", args->dtw_ahead, "online DTW window ahead of the estimate")
      ->check(non_negative_check());
  tuning->add_option("--posture-weight", args->posture_weight, "FeatureSpec posture_weight")
      ->check(non_negative_check());
  tuning
      ->add_option("--head-hands-posture-weight", args->head_hands_posture_weight,
                   "FeatureSpec head_hands_posture_weight (the posture weight of three points)")
      ->check(non_negative_check());
  tuning
      ->add_option("--root-velocity-weight", args->root_velocity_weight,
                   "FeatureSpec root_velocity_weight")
      ->check(non_negative_check());
  tuning
      ->add_option("--effector-speed-weight", args->effector_speed_weight,
                   "FeatureSpec effector_speed_weight")
      ->check(non_negative_check());
  tuning->add_option("--velocity-window", args->velocity_window, "FeatureSpec velocity_window_s")
      ->check(positive_check());
  return [args] { return run_eval(*args); };
}

}  // namespace duet::app
