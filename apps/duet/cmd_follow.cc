// duet follow --pair LEADER PARTNER [...] --input USER.bvh [--trace T.csv] [-o PARTNER.bvh]
#include <fmt/format.h>

#include "commands.h"
#include "duet/follow/hmm_follower.h"
#include "duet/io/atomic_write.h"
#include "duet/io/bvh.h"
#include "duet/live/follow_session.h"
#include "library_options.h"
#include "motion_options.h"
#include "progress.h"
#include "tracker_options.h"

namespace duet::app {

namespace {

struct FollowArgs {
  LibraryArgs library;
  std::string input;
  MotionFileOptions input_motion;
  TrackerArgs tracker;
  std::string trace_path;
  std::string output_path;
};

// The response clips must share one skeleton to be written into one output file.
bool responses_share_skeleton(const DuetLibrary& library) {
  const Skeleton& first = library.takes()[0].response_motion.clip.skeleton();
  for (const DuetTake& take : library.takes()) {
    const Skeleton& s = take.response_motion.clip.skeleton();
    if (s.joint_count() != first.joint_count()) return false;
    for (int j = 0; j < s.joint_count(); ++j) {
      if (s.joints[static_cast<std::size_t>(j)].name != first.joints[static_cast<std::size_t>(j)].name)
        return false;
    }
  }
  return true;
}

int run_follow(const FollowArgs& args) {
  std::optional<DuetLibrary> library = load_library(args.library, "follow");
  if (!library) return kExitFailure;
  if (!args.output_path.empty() && !responses_share_skeleton(*library)) {
    fmt::print(stderr, "duet follow: -o needs every partner file to share one skeleton\n");
    return kExitFailure;
  }

  MotionLoadOptions load_options;
  if (!make_load_options(args.input_motion, load_options)) return kExitFailure;
  Result<LoadedMotion> input = load_motion({args.input}, load_options);
  if (!input) {
    fmt::print(stderr, "duet follow: {}\n", input.error().message);
    return kExitFailure;
  }
  const Clip& user = input.value().clip;

  Result<std::unique_ptr<Tracker>> tracker = make_tracker(args.tracker, library->model());
  if (!tracker) {
    fmt::print(stderr, "duet follow: {}\n", tracker.error().message);
    return kExitFailure;
  }
  Result<FollowSession> session = FollowSession::create(
      *library, user.skeleton_ptr(), input.value().roles, std::move(tracker).value());
  if (!session) {
    fmt::print(stderr, "duet follow: {}\n", session.error().message);
    return kExitFailure;
  }

  const Clip& first_response = library->takes()[0].response_motion.clip;
  Clip partner(first_response.skeleton_ptr(), user.frame_rate(), user.frame_count());
  std::string trace = "frame,time_s,take,template_frame,confidence,jumped,lost\n";
  ProgressBar bar("following");
  int jumps = 0, lost = 0;
  double confidence_sum = 0.0;
  for (int f = 0; f < user.frame_count(); ++f) {
    const double time_s = f / user.frame_rate();
    const FollowResult r =
        session.value().step(user.translations_ls(f), user.rotations_ls(f), time_s);
    jumps += r.jumped ? 1 : 0;
    lost += r.lost ? 1 : 0;
    confidence_sum += r.confidence;
    fmt::format_to(std::back_inserter(trace), "{},{:.6f},{},{},{:.4f},{},{}\n", f, time_s, r.take,
                   r.frame_in_take, r.confidence, r.jumped ? 1 : 0, r.lost ? 1 : 0);
    if (!args.output_path.empty() && r.take >= 0) {
      const Clip& response = library->takes()[static_cast<std::size_t>(r.take)].response_motion.clip;
      std::ranges::copy(response.translations_ls(r.frame_in_take), partner.translations_ls(f).begin());
      std::ranges::copy(response.rotations_ls(r.frame_in_take), partner.rotations_ls(f).begin());
    }
    if (f % 64 == 0) bar.update(f, user.frame_count());
  }
  bar.update(user.frame_count(), user.frame_count());
  bar.finish();

  if (!args.trace_path.empty()) {
    if (Status s = write_file_atomically(args.trace_path, trace); !s) {
      fmt::print(stderr, "duet follow: {}\n", s.error().message);
      return kExitFailure;
    }
  }
  if (!args.output_path.empty()) {
    if (Status s = write_bvh(partner, args.output_path); !s) {
      fmt::print(stderr, "duet follow: {}\n", s.error().message);
      return kExitFailure;
    }
  }
  fmt::print("followed {} frames ({:.1f} s) against {} take(s), {} states: {} jumps, {} lost "
             "frames, mean confidence {:.3f}\n",
             user.frame_count(), user.duration(), library->takes().size(),
             library->model().num_states(), jumps, lost,
             user.frame_count() ? confidence_sum / user.frame_count() : 0.0);
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
  app.add_option("--trace", args->trace_path,
                 "Write one CSV row per input frame: "
                 "frame,time_s,take,template_frame,confidence,jumped,lost");
  app.add_option("-o,--output", args->output_path,
                 "Write the partner's motion (BVH, metres, the input's rate and frame count)");
  return [args] { return run_follow(*args); };
}

}  // namespace duet::app
