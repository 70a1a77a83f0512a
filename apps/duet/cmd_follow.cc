// duet follow --pair LEADER PARTNER [...] --input USER.bvh|USER.csv [--input-points P]
//             [--trace T.csv] [-o PARTNER.bvh]
// Runs the run-time loop of method.md 6 over a recorded performance: features, follower, partner
// synthesis with the corrections that are switched on.
#include <fmt/format.h>

#include "commands.h"
#include "duet/io/atomic_write.h"
#include "duet/io/bvh.h"
#include "duet/io/motion_argument.h"
#include "duet/live/follow_session.h"
#include "duet/live/live_loop.h"
#include "duet/motion/retarget.h"
#include "input_points.h"
#include "lost_diagnosis.h"
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
  std::string input_points;  // "", "full" or "head,hands" (--input-points)
  std::vector<double> device_offsets_cm;  // taken out of a three-point recording; empty: none
  double head_height_m = 0.0;  // the headset's height standing (--head-height); 0: learnt
  std::string calibration_path;  // --calibration: standing with both arms held forward
  std::string partner_rig;  // a motion word whose skeleton the partner is written on
  MotionFileOptions partner_rig_motion;
  bool allow_lost = false;
};

// The partner's motion on another skeleton (--partner-rig): retargeted and written in that rig
// file's units, so the user's own avatar can play it.
Status write_partner_on_rig(const FollowArgs& args, const Clip& partner,
                            const JointRoles& partner_roles, const Quat& user_to_y_up) {
  Result<std::vector<std::string>> paths = split_motion_argument(args.partner_rig);
  if (!paths) return Error{"--partner-rig: " + paths.error().message};
  MotionLoadOptions options;
  if (!make_load_options(args.partner_rig_motion, options)) {
    return Error{"--partner-rig: bad skeleton map"};
  }
  Result<LoadedMotion> rig = load_motion(paths.value(), options);
  if (!rig) return Error{"--partner-rig: " + rig.error().message};
  RetargetOptions retarget;
  set_head_corrections(retarget, partner, partner_roles, rig.value().clip, rig.value().roles);
  Result<Clip> moved = retarget_clip(partner, partner_roles, rig.value().clip.skeleton_ptr(),
                                     rig.value().roles, retarget, "the partner", args.partner_rig);
  if (!moved) return Error{"--partner-rig: " + moved.error().message};
  turn_to_file_world(moved.value(), user_to_y_up);  // into the user's world
  return write_bvh(moved.value(), args.output_path,
                   BvhWriteOptions::in_file_units(readable_metres_per_unit(
                       moved.value().skeleton(), rig.value().metres_per_unit)));
}

// The share of lost frames when the input is followed as the other dancer (at most the first
// minute): tells a swapped role or pair order from input that is no part of the dance.
std::optional<double> lost_as_other_role(const FollowArgs& args, const Clip& user,
                                         const JointRoles& roles, const FeatureSpec& features) {
  LibraryArgs other = args.library;
  other.role = other.role == "partner" ? "leader" : "partner";
  other.model_cache.clear();  // the cache holds this role's model; do not overwrite it
  // The captured takes answer the question; a grown library's copies add nothing to it but the
  // time to make them and to step through them (grown to 3 million states, a second of lost
  // input took 8.4 s and 1.2 GB with them, 4.2 s and 0.8 GB without).
  other.grow_to_states = 0;
  std::optional<DuetLibrary> library = load_library(other, "follow", features);
  if (!library) return std::nullopt;
  Result<std::unique_ptr<Tracker>> tracker = make_tracker(args.tracker, *library);
  if (!tracker) return std::nullopt;
  Result<FollowSession> session =
      FollowSession::create(*library, user.skeleton_ptr(), roles, std::move(tracker).value());
  if (!session) return std::nullopt;
  const int frames = std::min(user.frame_count(), static_cast<int>(60.0 * user.frame_rate()));
  int lost = 0;
  for (int f = 0; f < frames; ++f) {
    lost += session.value().step(user.translations_ls(f), user.rotations_ls(f),
                                 f / user.frame_rate()).lost ? 1 : 0;
  }
  return frames > 0 ? static_cast<double>(lost) / frames : 0.0;
}

// The BVH files are written in the units of the files they come from (the partner in the
// response takes', the user in the input's), so every duet command reads them back at the same
// scale and a viewer shows them as it shows the originals. An ASF+AMC source (read in metres) is
// written in its convention's BVH units, the ones a BVH with its joint names is read in. Both are
// written in the input's world: a Z-up input gets a Z-up partner, a tilted one a tilted partner
// (LoadedMotion::file_to_y_up).
Status write_outputs(const FollowArgs& args, const std::string& trace, const Clip& partner,
                     double partner_metres_per_unit, const Clip& user, const LoadedMotion& input) {
  if (!args.trace_path.empty()) {
    if (Status s = write_file_atomically(args.trace_path, trace); !s) return s;
  }
  // A clip in the input's world, and its file units; copied only when it has to be turned.
  auto write_in_input_world = [&](const Clip& clip, double metres_per_unit,
                                  const std::string& path) -> Status {
    const BvhWriteOptions units =
        BvhWriteOptions::in_file_units(readable_metres_per_unit(clip.skeleton(), metres_per_unit));
    const Quat to_y_up = input.file_to_y_up();
    if (to_y_up.vec().squaredNorm() == 0.0) return write_bvh(clip, path, units);
    Clip turned = clip;
    turn_to_file_world(turned, to_y_up);
    return write_bvh(turned, path, units);
  };
  if (!args.output_path.empty() && args.partner_rig.empty()) {
    if (Status s = write_in_input_world(partner, partner_metres_per_unit, args.output_path); !s) {
      return s;
    }
  }
  if (!args.user_output_path.empty()) {
    if (Status s = write_in_input_world(user, input.metres_per_unit, args.user_output_path); !s) {
      return s;
    }
  }
  return Ok{};
}

int run_follow(const FollowArgs& args) {
  MotionLoadOptions load_options;
  if (!make_load_options(args.input_motion, load_options)) return kExitFailure;
  Result<std::vector<std::string>> input_paths = split_motion_argument(args.input);
  if (!input_paths) {
    fmt::print(stderr, "duet follow: --input: {}\n", input_paths.error().message);
    return kExitUsage;
  }
  Result<LoadedMotion> input = load_motion(input_paths.value(), load_options);
  if (!input) {
    fmt::print(stderr, "duet follow: {}\n", input.error().message);
    return kExitFailure;
  }
  if (Status s = take_out_device_offsets(args.device_offsets_cm, input.value()); !s) {
    fmt::print(stderr, "duet follow: {}\n", s.error().message);
    return kExitUsage;
  }
  // Three points (a headset's recording, or --input-points head,hands) pick the three-point
  // follower; the library's templates then give the same three points.
  Result<InputPoints> points = choose_input_points(args.input_points, input.value());
  if (!points) {
    fmt::print(stderr, "duet follow: {}\n", points.error().message);
    return kExitUsage;
  }
  if (Status s = check_head_height_applies(args.head_height_m, points.value()); !s) {
    fmt::print(stderr, "duet follow: {}\n", s.error().message);
    return kExitUsage;
  }
  if (Status s = check_calibration_applies(args.calibration_path, points.value()); !s) {
    fmt::print(stderr, "duet follow: {}\n", s.error().message);
    return kExitUsage;
  }
  std::optional<BodyCalibration> calibration;
  if (!args.calibration_path.empty()) {
    Result<BodyCalibration> read =
        read_body_calibration(args.calibration_path, args.device_offsets_cm);
    if (!read) {
      fmt::print(stderr, "duet follow: {}\n", read.error().message);
      return kExitFailure;
    }
    calibration = read.value();
    const ArmsForward& arms = calibration->arms_forward;
    const double head_m = calibration->head_height_m;
    fmt::print(stderr,
               "duet follow: calibration {}: head {:.2f} m high standing, wrists held {:.2f} m "
               "apart and {:.2f} m in front of the head\n",
               args.calibration_path, head_m, (arms.wrists[0].x() - arms.wrists[1].x()) * head_m,
               0.5 * (arms.wrists[0].z() + arms.wrists[1].z()) * head_m);
  }
  FeatureSpec features;
  features.input_points = points.value();
  std::optional<DuetLibrary> loaded = load_library(args.library, "follow", features);
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
    std::vector<int> take_frames;
    for (const DuetTake& take : library->takes()) {
      take_frames.push_back(take.template_motion.clip.frame_count());
    }
    if (Status s = check_ground_truth(*truth, args.truth_path, take_frames); !s) {
      fmt::print(stderr, "duet follow: {}\n", s.error().message);
      return kExitFailure;
    }
  }

  const Clip& user = input.value().clip;
  if (truth && truth->rows.size() != static_cast<std::size_t>(user.frame_count())) {
    fmt::print(stderr, "duet follow: {}: {} rows of ground truth for {} input frames\n",
               args.truth_path, truth->rows.size(), user.frame_count());
    return kExitFailure;
  }

  Result<std::unique_ptr<Tracker>> tracker = make_tracker(args.tracker, *library);
  if (!tracker) {
    fmt::print(stderr, "duet follow: {}\n", tracker.error().message);
    return kExitFailure;
  }
  SourceSkeleton user_skeleton{
      user.skeleton_ptr(), input.value().roles, input.value().metres_per_unit, user.frame_rate(),
      head_joint_height_m(args.head_height_m, device_offsets_from_cm(args.device_offsets_cm))};
  if (calibration) {
    if (args.head_height_m == 0.0) user_skeleton.head_height_m = calibration->head_height_m;
    user_skeleton.arms_forward = calibration->arms_forward;
  }
  Result<LiveLoop> loop = LiveLoop::create(library, user_skeleton, std::move(tracker).value(),
                                           make_partner_params(args.partner));
  if (!loop) {
    fmt::print(stderr, "duet follow: {}\n", loop.error().message);
    return kExitFailure;
  }

  Clip partner(loop.value().partner_skeleton(), user.frame_rate(), user.frame_count());
  std::string trace =
      "frame,time_s,take,template_frame,confidence,jumped,lost,in_pause,best_distance_per_dim,"
      "sensor_noise_per_dim,missing,outlier,partly_observed,frame_offset\n";
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
    fmt::format_to(std::back_inserter(trace),
                   "{},{:.6f},{},{},{:.4f},{},{},{},{:.6f},{:.7f},{},{},{},{:.3f}\n", f,
                   frame.time_s, r.take, r.frame_in_take, r.confidence, r.jumped ? 1 : 0,
                   r.lost ? 1 : 0, r.in_pause ? 1 : 0, r.best_distance_per_dim,
                   r.sensor_noise_per_dim, r.missing ? 1 : 0, r.outlier ? 1 : 0,
                   r.partly_observed ? 1 : 0, r.frame_offset);
    std::ranges::copy(out.partner_translations_ls, partner.translations_ls(f).begin());
    std::ranges::copy(out.partner_rotations_ls, partner.rotations_ls(f).begin());
    if (f % 64 == 0) bar.update(f, user.frame_count());
  }
  bar.update(user.frame_count(), user.frame_count());
  bar.finish();

  if (Status s =
          write_outputs(args, trace, partner, library->takes()[0].response_motion.metres_per_unit,
                        user, input.value());
      !s) {
    fmt::print(stderr, "duet follow: {}\n", s.error().message);
    return kExitFailure;
  }
  if (!args.partner_rig.empty() && !args.output_path.empty()) {
    if (Status s = write_partner_on_rig(args, partner, library->takes()[0].response_motion.roles,
                                        input.value().file_to_y_up());
        !s) {
      fmt::print(stderr, "duet follow: {}\n", s.error().message);
      return kExitFailure;
    }
  }
  const LostSummary summary = summarise_lost(results);
  fmt::print(
      "followed {} frames ({:.1f} s) against {} take(s), {} states: {} jumps, {} lost "
      "frames{}; corrections: {}\n",
      user.frame_count(), user.duration(), library->takes().size(), library->model().num_states(),
      summary.jumps, summary.lost, describe_set_aside(summary),
      corrections_string(loop.value().params()));
  if (truth) print_accuracy_summary(*truth, results, library->frame_rate());
  if (points.value() == InputPoints::kHeadHands && args.head_height_m == 0.0 && !calibration) {
    if (std::optional<std::string> note = head_height_note(
            user, input.value().roles, device_offsets_from_cm(args.device_offsets_cm))) {
      fmt::print(stderr, "duet follow: note: {}\n", *note);
    }
  }
  if (points.value() == InputPoints::kHeadHands && !calibration) {
    if (std::optional<std::string> note = calibration_note(results, user.frame_rate())) {
      fmt::print(stderr, "duet follow: note: {}\n", *note);
    }
  }
  const float median_tempo = median_followed_tempo(results);
  if (summary.lost_fraction() <= kMostlyLostFraction) {
    // Followed, but perhaps in slow or fast motion: the rate is the one cause worth a warning.
    if (std::optional<std::string> rate =
            rate_mismatch(user.frame_rate(), library->frame_rate(), median_tempo)) {
      fmt::print(stderr, "duet follow: warning: {}\n", *rate);
    }
    return kExitOk;
  }

  // Most of the input was lost: say why it may be, and fail unless that was the point.
  LostContext context;
  context.input = &input.value();
  context.input_rate_hz = user.frame_rate();
  context.library_rate_hz = library->frame_rate();
  parse_dancer_role(args.library.role, context.role);
  context.median_tempo = median_tempo;
  context.other_role_lost_fraction = lost_as_other_role(args, user, input.value().roles, features);
  fmt::print(stderr, "duet follow: {:.0f}% of the input's frames are lost (no part of the library "
             "explains them). Likely causes:\n", 100.0 * summary.lost_fraction());
  for (const std::string& cause : diagnose_lost(summary, context)) {
    fmt::print(stderr, "  - {}\n", cause);
  }
  if (args.allow_lost) return kExitOk;
  fmt::print(stderr, "duet follow: exit {} (mostly lost; --allow-lost keeps exit 0)\n", kExitLost);
  return kExitLost;
}

}  // namespace

Command register_follow(CLI::App& app) {
  auto args = std::make_shared<FollowArgs>();
  add_library_options(app, args->library);
  app.add_option("--input", args->input,
                 "The user's motion: a BVH file, or SKELETON.asf+MOTION.amc; any rig whose body "
                 "roles are found (duet inspect shows them); or a three-point CSV (head and "
                 "hands, docs/file-formats.md)")
      ->required();
  app.add_option("--input-points", args->input_points, kInputPointsHelp)
      ->check(input_points_choice(true));
  add_device_offsets_option(app, args->device_offsets_cm,
                            "Taken out of a three-point recording before following (a recording "
                            "of duet serve --source xr has them out already; default: none)");
  add_head_height_option(app, args->head_height_m);
  add_calibration_option(app, args->calibration_path);
  add_motion_file_options(app, args->input_motion, "input-");
  add_tracker_options(app, args->tracker);
  add_partner_options(app, args->partner);
  app.add_option("--trace", args->trace_path,
                 "Write one CSV row per input frame: "
                 "frame,time_s,take,template_frame,confidence,jumped,lost,in_pause,"
                 "best_distance_per_dim,sensor_noise_per_dim,missing,outlier,partly_observed,"
                 "frame_offset "
                 "(missing: no usable pose, or the sensor repeated the last one; outlier: a frame "
                 "nothing explained, its evidence set aside; partly_observed: three points with "
                 "a controller repeating its last pose, the head and the other hand evidence; "
                 "frame_offset: where between template frames the dancer is, from "
                 "template_frame)");
  app.add_option("-o,--output", args->output_path,
                 "Write the partner's motion: BVH in the response takes' units, in the user's "
                 "world frame, at the input's rate and frame count");
  app.add_option("--user-output", args->user_output_path,
                 "Also write the user's motion (BVH in the input's units), sharing the partner "
                 "file's world frame (open both together to see the duet)");
  app.add_option("--partner-rig", args->partner_rig,
                 "Write the partner (-o) on this skeleton instead of the library's, e.g. your own "
                 "avatar's BVH (or SKELETON.asf+MOTION.amc): retargeted by role directions with the "
                 "feet on the floor, in that file's units (docs/retarget.md)")
      ->needs("--output");
  add_motion_file_options(app, args->partner_rig_motion, "partner-rig-");
  app.add_flag("--allow-lost", args->allow_lost,
               "Exit 0 even when over half the input's frames are lost (by default duet follow "
               "then lists the likely causes and exits 3). A followed input whose median tempo "
               "is outside 0.66-1.5x the library's gets a warning naming the frame rate to pass");
  app.add_option("--truth", args->truth_path,
                 "Ground truth CSV from `duet improvise` with the same pairs in the same order: "
                 "print the follower's accuracy (a take or frame the library lacks is an error)")
      ->check(CLI::ExistingFile);
  return [args] { return run_follow(*args); };
}

}  // namespace duet::app
