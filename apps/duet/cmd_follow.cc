// duet follow --pair LEADER PARTNER [...] --input USER.bvh [--trace T.csv] [-o PARTNER.bvh]
// Runs the run-time loop of method.md 6 over a recorded performance: features, follower, partner
// synthesis with the corrections that are switched on.
#include <fmt/format.h>

#include "commands.h"
#include "duet/io/atomic_write.h"
#include "duet/io/bvh.h"
#include "duet/live/live_loop.h"
#include "library_options.h"
#include "motion_options.h"
#include "partner_options.h"
#include "progress.h"
#include "tracker_options.h"
#include "truth_summary.h"

namespace duet::app {

namespace {

struct FollowArgs {
  LibraryArgs library;
  std::string input;
  MotionFileOptions input_motion;
  TrackerArgs tracker;
  PartnerArgs partner;
  std::string trace_path;
  std::string output_path;
  std::string user_output_path;
  std::string truth_path;
};

// The BVH files are written in the units of the files they come from (the partner in the
// response takes', the user in the input's), so every duet command reads them back at the same
// scale and a viewer shows them as it shows the originals.
Status write_outputs(const FollowArgs& args, const std::string& trace, const Clip& partner,
                     double partner_metres_per_unit, const Clip& user,
                     double user_metres_per_unit) {
  if (!args.trace_path.empty()) {
    if (Status s = write_file_atomically(args.trace_path, trace); !s) return s;
  }
  if (!args.output_path.empty()) {
    const BvhWriteOptions units = BvhWriteOptions::in_file_units(partner_metres_per_unit);
    if (Status s = write_bvh(partner, args.output_path, units); !s) return s;
  }
  if (!args.user_output_path.empty()) {
    const BvhWriteOptions units = BvhWriteOptions::in_file_units(user_metres_per_unit);
    if (Status s = write_bvh(user, args.user_output_path, units); !s) return s;
  }
  return Ok{};
}

int run_follow(const FollowArgs& args) {
  std::optional<DuetLibrary> loaded = load_library(args.library, "follow");
  if (!loaded) return kExitFailure;
  auto library = std::make_shared<const DuetLibrary>(std::move(*loaded));

  std::optional<GroundTruth> truth;
  if (!args.truth_path.empty()) {
    Result<GroundTruth> read = read_ground_truth(args.truth_path);
    if (!read) {
      fmt::print(stderr, "duet follow: {}\n", read.error().message);
      return kExitFailure;
    }
    truth = std::move(read).value();
  }

  MotionLoadOptions load_options;
  if (!make_load_options(args.input_motion, load_options)) return kExitFailure;
  Result<LoadedMotion> input = load_motion({args.input}, load_options);
  if (!input) {
    fmt::print(stderr, "duet follow: {}\n", input.error().message);
    return kExitFailure;
  }
  const Clip& user = input.value().clip;
  if (truth && truth->rows.size() != static_cast<std::size_t>(user.frame_count())) {
    fmt::print(stderr, "duet follow: {}: {} rows of ground truth for {} input frames\n",
               args.truth_path, truth->rows.size(), user.frame_count());
    return kExitFailure;
  }

  Result<std::unique_ptr<Tracker>> tracker = make_tracker(args.tracker, library->model());
  if (!tracker) {
    fmt::print(stderr, "duet follow: {}\n", tracker.error().message);
    return kExitFailure;
  }
  SourceSkeleton user_skeleton{user.skeleton_ptr(), input.value().roles,
                               input.value().metres_per_unit, user.frame_rate()};
  Result<LiveLoop> loop = LiveLoop::create(library, user_skeleton, std::move(tracker).value(),
                                           make_partner_params(args.partner));
  if (!loop) {
    fmt::print(stderr, "duet follow: {}\n", loop.error().message);
    return kExitFailure;
  }

  Clip partner(loop.value().partner_skeleton(), user.frame_rate(), user.frame_count());
  std::string trace = "frame,time_s,take,template_frame,confidence,jumped,lost\n";
  std::vector<FollowResult> results;
  results.reserve(static_cast<std::size_t>(user.frame_count()));
  SourceFrame frame;
  frame.resize(user.joint_count());
  ProgressBar bar("following");
  for (int f = 0; f < user.frame_count(); ++f) {
    frame.time_s = f / user.frame_rate();
    frame.arrival = SteadyClock::now();
    std::ranges::copy(user.translations_ls(f), frame.translations_ls.begin());
    std::ranges::copy(user.rotations_ls(f), frame.rotations_ls.begin());
    const LiveOutput& out = loop.value().step(frame);
    const FollowResult& r = out.follow;
    results.push_back(r);
    fmt::format_to(std::back_inserter(trace), "{},{:.6f},{},{},{:.4f},{},{}\n", f, frame.time_s,
                   r.take, r.frame_in_take, r.confidence, r.jumped ? 1 : 0, r.lost ? 1 : 0);
    std::ranges::copy(out.partner_translations_ls, partner.translations_ls(f).begin());
    std::ranges::copy(out.partner_rotations_ls, partner.rotations_ls(f).begin());
    if (f % 64 == 0) bar.update(f, user.frame_count());
  }
  bar.update(user.frame_count(), user.frame_count());
  bar.finish();

  if (Status s =
          write_outputs(args, trace, partner, library->takes()[0].response_motion.metres_per_unit,
                        user, input.value().metres_per_unit);
      !s) {
    fmt::print(stderr, "duet follow: {}\n", s.error().message);
    return kExitFailure;
  }
  int jumps = 0, lost = 0;
  for (const FollowResult& r : results) {
    jumps += r.jumped ? 1 : 0;
    lost += r.lost ? 1 : 0;
  }
  fmt::print(
      "followed {} frames ({:.1f} s) against {} take(s), {} states: {} jumps, {} lost "
      "frames; corrections: {}\n",
      user.frame_count(), user.duration(), library->takes().size(), library->model().num_states(),
      jumps, lost, corrections_string(loop.value().params()));
  if (truth) print_accuracy_summary(*truth, results, library->frame_rate());
  return kExitOk;
}

}  // namespace

Command register_follow(CLI::App& app) {
  auto args = std::make_shared<FollowArgs>();
  add_library_options(app, args->library);
  app.add_option("--input", args->input, "The user's motion (BVH)")
      ->required()
      ->check(CLI::ExistingFile);
  add_motion_file_options(app, args->input_motion, "input-");
  add_tracker_options(app, args->tracker);
  add_partner_options(app, args->partner);
  app.add_option("--trace", args->trace_path,
                 "Write one CSV row per input frame: "
                 "frame,time_s,take,template_frame,confidence,jumped,lost");
  app.add_option("-o,--output", args->output_path,
                 "Write the partner's motion: BVH in the response takes' units, in the user's "
                 "world frame, at the input's rate and frame count");
  app.add_option("--user-output", args->user_output_path,
                 "Also write the user's motion (BVH in the input's units), sharing the partner "
                 "file's world frame (open both together to see the duet)");
  app.add_option("--truth", args->truth_path,
                 "Ground truth CSV from `duet improvise`: print the follower's accuracy")
      ->check(CLI::ExistingFile);
  return [args] { return run_follow(*args); };
}

}  // namespace duet::app
