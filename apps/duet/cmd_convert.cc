// duet convert INPUT... -o OUT.bvh [--fps F] [--scale S] [--units-per-metre U]
// duet convert INPUT... --points head,hands -o OUT.csv   (a three-point recording)
#include <fmt/format.h>

#include <cmath>

#include "commands.h"
#include "duet/io/atomic_write.h"
#include "duet/io/bvh.h"
#include "duet/io/motion_argument.h"
#include "duet/io/motion_file.h"
#include "duet/io/points_csv.h"
#include "duet/motion/head_hands.h"
#include "duet/motion/limits.h"
#include "duet/motion/resample.h"
#include "input_points.h"
#include "library_options.h"
#include "motion_options.h"
#include "number_checks.h"

namespace duet::app {

namespace {

struct ConvertArgs {
  std::vector<std::string> inputs;
  std::string output;
  MotionFileOptions input;
  std::optional<double> output_fps;
  std::optional<double> output_units_per_metre;  // default: units duet reads back unaided
  std::string points;  // "head,hands": write the three-point CSV of the motion
  std::vector<double> device_offsets_cm;  // where the points sit; empty: at the joints
};

// The three points a headset and controllers would have reported (duet/io/points_csv.h).
int write_points(const LoadedMotion& loaded, const Clip& clip, const ConvertArgs& args) {
  const std::string& output = args.output;
  Result<Clip> points =
      head_hands_clip(clip, loaded.roles, device_offsets_from_cm(args.device_offsets_cm));
  if (!points) {
    fmt::print(stderr, "duet convert: {}: {}\n", loaded.description, points.error().message);
    return kExitFailure;
  }
  Status written = write_file_atomically(output, format_points_csv(points.value()));
  if (!written) {
    fmt::print(stderr, "duet convert: {}\n", written.error().message);
    return kExitFailure;
  }
  fmt::print(stderr, "wrote {}: {} samples of head and hands at {:.6g} Hz\n", output,
             points.value().frame_count(), points.value().frame_rate());
  return kExitOk;
}

int run_convert(const ConvertArgs& args) {
  if (args.points.empty() && is_points_csv_path(args.output)) {
    fmt::print(stderr,
               "duet convert: {} is a .csv: a CSV output holds three points; add --points "
               "head,hands (or name a .bvh output)\n",
               args.output);
    return kExitFailure;
  }
  if (args.points.empty() && !args.device_offsets_cm.empty()) {
    fmt::print(stderr, "duet convert: --device-offsets-cm applies to --points head,hands\n");
    return kExitUsage;
  }
  MotionLoadOptions load_options;
  if (!make_load_options(args.input, load_options)) return kExitFailure;
  // One word may name an ASF+AMC pair, as every other command takes it ("60.asf+60_01.amc").
  std::vector<std::string> files = args.inputs;
  if (files.size() == 1) {
    Result<std::vector<std::string>> split = split_motion_argument(files[0]);
    if (!split) {
      fmt::print(stderr, "duet convert: {}\n", split.error().message);
      return kExitFailure;
    }
    files = std::move(split).value();
  }
  Result<LoadedMotion> loaded = load_motion(files, load_options);
  if (!loaded) {
    fmt::print(stderr, "duet convert: {}\n", loaded.error().message);
    return kExitFailure;
  }
  Clip clip = std::move(loaded.value().clip);
  if (args.output_fps && *args.output_fps != clip.frame_rate()) {
    // 1000 fps from a long file can still be too many frames: say so rather than exhaust memory.
    const double frames = resampled_frame_count(clip, *args.output_fps);
    if (!(frames <= static_cast<double>(kMaxClipFrames))) {
      fmt::print(stderr,
                 "duet convert: --fps {:g} would make {:.4g} frames of {}, over the limit of {} "
                 "frames per clip\n",
                 *args.output_fps, frames, loaded.value().description, kMaxClipFrames);
      return kExitFailure;
    }
    clip = resample(clip, *args.output_fps);
  }
  if (!args.points.empty()) return write_points(loaded.value(), clip, args);
  // The BVH keeps the source's world: a Z-up file stays Z-up (the points CSV above is Y-up, as
  // headsets report).
  turn_to_file_world(clip, loaded.value().file_to_y_up());
  // A BVH cannot say its units: by default write the ones the reader will infer for this
  // skeleton (the source's, or its convention's), so the file reads back at its true size.
  const double readable_units_per_metre =
      1.0 / readable_metres_per_unit(clip.skeleton(), loaded.value().metres_per_unit);
  BvhWriteOptions write_options;
  write_options.units_per_metre = args.output_units_per_metre.value_or(readable_units_per_metre);
  Status written = write_bvh(clip, args.output, write_options);
  if (!written) {
    fmt::print(stderr, "duet convert: {}\n", written.error().message);
    return kExitFailure;
  }
  fmt::print(stderr, "wrote {}: {} frames at {:.6g} fps, {} joints, {:.6g} units per metre\n",
             args.output, clip.frame_count(), clip.frame_rate(),
             clip.skeleton().animated_joint_count(), write_options.units_per_metre);
  if (std::abs(write_options.units_per_metre - readable_units_per_metre) >
      1e-9 * readable_units_per_metre) {
    fmt::print(stderr,
               "duet convert: note: duet reads this skeleton at {:.6g} units per metre; read {} "
               "with --scale {:.6g}\n",
               readable_units_per_metre, args.output, 1.0 / write_options.units_per_metre);
  }
  return kExitOk;
}

}  // namespace

Command register_convert(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  app.add_option("inputs", args->inputs,
                 "A .bvh file, or an .asf and an .amc file (two words, or one: "
                 "SKELETON.asf+MOTION.amc as the other commands take it)")
      ->required()
      ->expected(1, 2)
      ->check(CLI::ExistingFile | motion_word_check());
  app.add_option("-o,--output", args->output,
                 "Output BVH file, or CSV with --points (written atomically)")
      ->required();
  app.add_option("--points", args->points,
                 "Write only the head and both hands as a three-point CSV (the only value: "
                 "head,hands; docs/file-formats.md)")
      ->check(input_points_choice(false));
  add_device_offsets_option(app, args->device_offsets_cm,
                            "The points are put there: what a headset and controllers would "
                            "record (default: at the joints)");
  app.add_option("--input-fps", args->input.fps, "Frame rate of the input, overriding its header")
      ->check(fps_check());
  app.add_option("--scale", args->input.scale,
                 "Metres per input file unit (default: known per skeleton convention)")
      ->check(scale_check());
  app.add_option("--map", args->input.map_path, "Skeleton map JSON for the input")
      ->check(CLI::ExistingFile);
  app.add_option("--fps", args->output_fps,
                 "Resample to this frame rate (quaternion interpolation)")
      ->check(fps_check());
  app.add_option("--units-per-metre", args->output_units_per_metre,
                 "Length units of the output per metre (default: the units duet reads back for "
                 "the skeleton: the source's, e.g. salsa DAZ 0.768, CMU 17.72; metres for other "
                 "rigs)")
      ->check(number_between(1.0 / kMaxScale, 1.0 / kMinScale, "units per metre"));
  return [args] { return run_convert(*args); };
}

}  // namespace duet::app
