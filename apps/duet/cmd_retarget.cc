// duet retarget INPUT... --rig RIG.bvh -o OUT.bvh: a motion put onto another skeleton
// (docs/retarget.md).
#include <fmt/format.h>

#include <filesystem>
#include <system_error>

#include "commands.h"
#include "duet/io/bvh.h"
#include "duet/io/motion_argument.h"
#include "duet/io/motion_file.h"
#include "duet/motion/generic_rigs.h"
#include "duet/motion/retarget.h"
#include "duet/motion/rig_variants.h"
#include "library_options.h"
#include "motion_options.h"
#include "number_checks.h"

namespace duet::app {

namespace {

struct RetargetArgs {
  std::vector<std::string> inputs;
  std::vector<std::string> rig;
  std::string output;
  MotionFileOptions input;
  std::optional<double> rig_scale;
  std::string rig_map_path;
  std::string proportions;
  std::optional<double> stride_scale;
  bool no_feet = false;
};

// The generic rig (generic_rigs.h) a --rig word names, when it names one and no file.
const GenericRigInfo* generic_rig_named(const std::vector<std::string>& words) {
  if (words.size() != 1) return nullptr;
  std::error_code ec;  // a name too long for a path is no file either, not an exception
  if (std::filesystem::exists(words.front(), ec)) return nullptr;
  return find_generic_rig(words.front());
}

// A --rig word: a motion file (motion_word_check), or a generic rig's name.
CLI::Validator rig_word_check() {
  return CLI::Validator(
      [](std::string& word) -> std::string {
        if (generic_rig_named({word}) != nullptr) return {};
        Result<std::vector<std::string>> split = split_motion_argument(word);
        if (split) return {};
        std::string names;
        for (const GenericRigInfo& rig : generic_rigs()) names += ", " + std::string(rig.name);
        return split.error().message + " (nor a rig made in code:" + names.substr(1) + ")";
      },
      "MOTION", "");
}

// The rig as a BVH file can carry it: a root with position channels and three rotation channels
// on every joint (a rig read from a file with fewer would drop the retargeted rotations).
Skeleton writable(Skeleton skeleton) {
  for (Joint& joint : skeleton.joints) {
    if (joint.end_site) continue;
    std::vector<Channel> channels;
    if (joint.parent < 0 || joint.has_position_channels()) {
      channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition};
    }
    int rotations = 0;
    for (const Channel c : joint.channels) rotations += is_position_channel(c) ? 0 : 1;
    if (rotations == 3) {
      for (const Channel c : joint.channels) {
        if (!is_position_channel(c)) channels.push_back(c);
      }
    } else {
      channels.insert(channels.end(),
                      {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation});
    }
    joint.channels = std::move(channels);
  }
  return skeleton;
}

int run_retarget(const RetargetArgs& args) {
  if (args.rig.empty() && args.proportions.empty()) {
    fmt::print(stderr,
               "duet retarget: give the target skeleton with --rig, or --proportions to "
               "retarget onto a proportioned copy of the input's own skeleton\n");
    return kExitUsage;
  }
  RigProportions proportions;
  if (std::string error;
      !args.proportions.empty() && !parse_rig_proportions(args.proportions, proportions, error)) {
    fmt::print(stderr, "duet retarget: --proportions {}\n", error);
    return kExitUsage;
  }

  const GenericRigInfo* generic = generic_rig_named(args.rig);
  if (generic != nullptr && (args.rig_scale || !args.rig_map_path.empty())) {
    fmt::print(stderr,
               "duet retarget: --rig {} is a rig made in code, in metres with its own roles: "
               "--rig-scale and --rig-map do not apply\n",
               generic->name);
    return kExitUsage;
  }

  // One word may be SKELETON.asf+MOTION.amc, as everywhere else a motion is taken.
  std::vector<std::string> inputs = args.inputs;
  std::vector<std::string> rig_files = generic != nullptr ? std::vector<std::string>{} : args.rig;
  for (std::vector<std::string>* files : {&inputs, &rig_files}) {
    if (files->size() != 1) continue;
    Result<std::vector<std::string>> split = split_motion_argument(files->front());
    if (!split) {
      fmt::print(stderr, "duet retarget: {}\n", split.error().message);
      return kExitUsage;
    }
    *files = split.value();
  }

  MotionLoadOptions load_options;
  if (!make_load_options(args.input, load_options)) return kExitFailure;
  Result<LoadedMotion> source = load_motion(inputs, load_options);
  if (!source) {
    fmt::print(stderr, "duet retarget: {}\n", source.error().message);
    return kExitFailure;
  }

  // The target: the rig file's skeleton (its motion says only where its head faces, when its
  // rest pose is no standing body), or the input's own.
  Skeleton rig_skeleton = source.value().clip.skeleton();
  JointRoles rig_roles = source.value().roles;
  RetargetOptions options;
  options.stride_scale = args.stride_scale;
  options.feet_on_floor = !args.no_feet;
  double rig_metres_per_unit = source.value().metres_per_unit;
  std::string rig_name = source.value().description;
  if (!rig_files.empty()) {
    MotionFileOptions rig_input;
    rig_input.scale = args.rig_scale;
    rig_input.map_path = args.rig_map_path;
    MotionLoadOptions rig_options;
    if (!make_load_options(rig_input, rig_options)) return kExitFailure;
    Result<LoadedMotion> rig = load_motion(rig_files, rig_options);
    if (!rig) {
      fmt::print(stderr, "duet retarget: rig: {}\n", rig.error().message);
      return kExitFailure;
    }
    rig_skeleton = rig.value().clip.skeleton();
    rig_roles = rig.value().roles;
    set_head_corrections(options, source.value().clip, source.value().roles, rig.value().clip,
                         rig_roles);
    rig_metres_per_unit = rig.value().metres_per_unit;
    rig_name = rig.value().description;
  }
  if (generic != nullptr) {
    Result<GenericRigWithRoles> made = make_generic_rig_with_roles(generic->rig);
    if (!made) {
      fmt::print(stderr, "duet retarget: rig {}: {}\n", generic->name, made.error().message);
      return kExitFailure;
    }
    rig_skeleton = std::move(made.value().skeleton);
    rig_roles = std::move(made.value().roles);
    rig_metres_per_unit = 1.0;
    rig_name = std::string(generic->name) + " (a rig made in code, docs/retarget.md)";
  }
  if (!args.proportions.empty()) {
    rig_skeleton = make_proportioned_rig(rig_skeleton, rig_roles, proportions);
    rig_name += " (proportioned: " + args.proportions + ")";
  }
  auto target = std::make_shared<const Skeleton>(writable(std::move(rig_skeleton)));

  Result<Retargeter> retargeter =
      Retargeter::create(source.value().clip.skeleton_ptr(), source.value().roles, target,
                         rig_roles, options, source.value().description, rig_name);
  if (!retargeter) {
    fmt::print(stderr, "duet retarget: {}\n", retargeter.error().message);
    return kExitFailure;
  }
  const Clip& in = source.value().clip;
  Clip out(target, in.frame_rate(), in.frame_count());
  for (int f = 0; f < in.frame_count(); ++f) {
    retargeter.value().retarget_frame(in.translations_ls(f), in.rotations_ls(f),
                                      out.translations_ls(f), out.rotations_ls(f));
  }
  // In the source's world (a Z-up source gives a Z-up output) and the rig file's units; an ASF
  // rig (read in metres) in its convention's BVH units.
  turn_to_file_world(out, source.value().file_to_y_up());
  const double written_metres_per_unit = readable_metres_per_unit(*target, rig_metres_per_unit);
  Status written =
      write_bvh(out, args.output, BvhWriteOptions::in_file_units(written_metres_per_unit));
  if (!written) {
    fmt::print(stderr, "duet retarget: {}\n", written.error().message);
    return kExitFailure;
  }
  fmt::print(stderr,
             "wrote {}: {} frames at {:.6g} fps on {} ({} joints, {:.6g} m per unit), stride "
             "scale {:.4f}\n",
             args.output, out.frame_count(), out.frame_rate(), rig_name,
             target->animated_joint_count(), written_metres_per_unit,
             retargeter.value().stride_scale());
  return kExitOk;
}

}  // namespace

Command register_retarget(CLI::App& app) {
  auto args = std::make_shared<RetargetArgs>();
  app.add_option("inputs", args->inputs,
                 "The motion: a .bvh file, or an .asf and an .amc file (as two words or as one, "
                 "SKELETON.asf+MOTION.amc)")
      ->required()
      ->expected(1, 2)
      ->check(motion_word_check());
  app.add_option("--rig", args->rig,
                 "The target skeleton: a .bvh file (its motion only tells where its head faces "
                 "when its rest pose is no standing body), or an .asf and an "
                 ".amc file (two words, or SKELETON.asf+MOTION.amc); the output is written in its "
                 "units. Or a rig made in code (written in metres): game-avatar, depth-camera, "
                 "inertial-suit (docs/retarget.md). Put it after the input (it takes up to two "
                 "files)")
      ->expected(1, 2)
      ->check(rig_word_check());
  app.add_option("-o,--output", args->output, "Output BVH file (written atomically)")->required();
  add_motion_file_options(app, args->input);
  app.add_option("--rig-scale", args->rig_scale,
                 "Metres per unit of the rig file, and of the output (default: known per skeleton "
                 "convention, else guessed from the body's height)")
      ->check(scale_check());
  app.add_option("--rig-map", args->rig_map_path,
                 "Skeleton map JSON naming the joint of each role in the rig")
      ->check(CLI::ExistingFile);
  app.add_option("--proportions", args->proportions,
                 "Retarget onto a proportioned copy of the rig (of the input's skeleton without "
                 "--rig): arms=F,legs=F,trunk=F length factors, arms_down=DEG (A-pose), "
                 "legs_apart=DEG, lean=DEG, toes_out=DEG; e.g. arms=1.1,legs=0.92,trunk=1.05");
  app.add_option("--stride-scale", args->stride_scale,
                 "Scale of the root's path (default: rig leg length / input leg length)")
      ->check(number_between(0.1, 10.0));
  app.add_flag("--no-feet", args->no_feet,
               "Do not put the rig's lowest foot at the input's (scaled) height every frame; "
               "scale the pelvis height instead");
  return [args] { return run_retarget(*args); };
}

}  // namespace duet::app
