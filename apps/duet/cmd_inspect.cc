// duet inspect FILE.bvh | SKELETON.asf MOTION.amc [--json]
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "duet/io/motion_file.h"
#include "duet/motion/arms_forward.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"
#include "motion_options.h"

namespace duet::app {

namespace {

struct InspectArgs {
  std::vector<std::string> files;
  MotionFileOptions motion;
  bool json = false;
};

// Why this file cannot drive the follower (empty when it can): roles missing, or a body whose
// height says the units are wrong.
std::vector<std::string> follower_problems(const LoadedMotion& m) {
  std::vector<std::string> problems;
  if (!m.role_detection.complete()) {
    std::string missing;
    for (Role r : m.role_detection.missing_roles()) {
      missing += (missing.empty() ? "" : ", ") + std::string(role_name(r));
    }
    problems.push_back("roles missing: " + missing + " (give a skeleton map with --map)");
  }
  if (!m.units_warning.empty()) problems.push_back(m.units_warning);
  return problems;
}

std::string joint_name(const Skeleton& skeleton, int joint) {
  return joint >= 0 && joint < skeleton.joint_count()
             ? skeleton.joints[static_cast<std::size_t>(joint)].name
             : std::string("-");
}

int run_inspect(const InspectArgs& args) {
  MotionLoadOptions load_options;
  if (!make_load_options(args.motion, load_options)) return kExitFailure;
  load_options.require_roles = false;  // an unknown rig is still inspectable
  Result<LoadedMotion> loaded = load_motion(args.files, load_options);
  if (!loaded) {
    fmt::print(stderr, "duet inspect: {}\n", loaded.error().message);
    return kExitFailure;
  }
  const LoadedMotion& motion = loaded.value();
  const Clip& clip = motion.clip;
  const Skeleton& skeleton = clip.skeleton();
  const std::vector<std::string> problems = follower_problems(motion);
  const BodyDimensions& body = motion.body;
  // Whether the rest pose is a standing body can be told only with every role found.
  const bool full_body_roles =
      motion.role_detection.complete() && !is_head_hands_input(motion.roles);

  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 high = -low;
  // In the file's own world (the clip was turned to Y-up on loading).
  const Quat to_file_world = motion.file_to_y_up().conjugate();
  const std::vector<Vec3> positions = world_positions(clip);
  for (const Vec3& p : positions) {
    low = low.cwiseMin(to_file_world * p);
    high = high.cwiseMax(to_file_world * p);
  }
  if (positions.empty()) low = high = Vec3::Zero();
  // Three points: whether the file holds a body calibration's pose (arms_forward.h), as duet
  // follow --calibration would read it.
  std::optional<Result<ArmsForward>> calibration;
  if (is_head_hands_input(motion.roles) && clip.joint_count() == kHeadHandsJointCount) {
    calibration = arms_forward_of_points(clip);
  }
  const double pose_head_m = calibration ? median_head_height(clip) : 0.0;

  if (args.json) {
    nlohmann::json doc;
    doc["file"] = motion.description;
    doc["joints"] = skeleton.animated_joint_count();
    doc["end_sites"] = skeleton.joint_count() - skeleton.animated_joint_count();
    doc["frames"] = clip.frame_count();
    doc["fps"] = clip.frame_rate();
    doc["duration_s"] = clip.duration();
    doc["channels"] = skeleton.channel_count();
    doc["convention"] = motion.roles.convention;
    doc["metres_per_unit"] = motion.metres_per_unit;
    doc["units"] = {{"name", motion.units_name},
                    {"source", motion.units_source},
                    {"warning", motion.units_warning}};
    doc["up_axis"] = {{"axis", std::string(up_axis_name(motion.up_axis))},
                      {"source", motion.up_source},
                      {"levelled_by_deg", motion.tilt_deg()},
                      {"warning", motion.up_warning}};
    if (body.valid()) {
      doc["body_m"] = {{"standing_height", body.standing_height_m},
                       {"leg_length", body.leg_length_m},
                       {"arm_length", body.arm_length_m},
                       {"trunk_length", body.trunk_length_m},
                       {"hip_width", body.hip_width_m}};
    } else {
      doc["body_m"] = nullptr;
    }
    nlohmann::json roles = nlohmann::json::object();
    for (int r = 0; r < kRoleCount; ++r) {
      const int joint = motion.roles.joints[static_cast<std::size_t>(r)];
      roles[std::string(role_name(static_cast<Role>(r)))] = {
          {"joint", joint >= 0 ? nlohmann::json(joint_name(skeleton, joint)) : nlohmann::json()},
          {"how", motion.role_detection.notes[static_cast<std::size_t>(r)]}};
    }
    doc["roles"] = roles;
    doc["roles_problem"] = motion.role_detection.problem;
    doc["can_drive_follower"] = problems.empty();
    doc["input_points"] = is_head_hands_input(motion.roles) ? "head,hands" : "full";
    doc["rest_pose_stands"] =
        full_body_roles ? nlohmann::json(rest_pose_stands(skeleton, motion.roles)) : nullptr;
    doc["follower_problems"] = problems;
    if (calibration && static_cast<bool>(*calibration)) {
      const ArmsForward& arms = calibration->value();
      doc["calibration"] = {
          {"usable", true},
          {"head_height_m", pose_head_m},
          {"wrists_apart_m", (arms.wrists[0].x() - arms.wrists[1].x()) * pose_head_m},
          {"wrists_ahead_m", 0.5 * (arms.wrists[0].z() + arms.wrists[1].z()) * pose_head_m}};
    } else if (calibration) {
      doc["calibration"] = {{"usable", false}, {"reason", calibration->error().message}};
    } else {
      doc["calibration"] = nullptr;
    }
    doc["bounding_box_m"] = {{"min", {low.x(), low.y(), low.z()}},
                             {"max", {high.x(), high.y(), high.z()}}};
    nlohmann::json names = nlohmann::json::array();
    for (const Joint& j : skeleton.joints) {
      if (!j.end_site) names.push_back(j.name);
    }
    doc["joint_names"] = names;
    // Names from the file may be any bytes: invalid UTF-8 becomes U+FFFD instead of throwing.
    std::cout << doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    return kExitOk;
  }
  fmt::print("file:        {}\n", motion.description);
  fmt::print("convention:  {} ({:.6g} m per file unit)\n", motion.roles.convention,
             motion.metres_per_unit);
  fmt::print("units:       {}{}\n",
             motion.units_name.empty() ? fmt::format("{:.6g} m", motion.metres_per_unit)
                                       : motion.units_name,
             motion.units_source.empty() ? "" : ", " + motion.units_source);
  fmt::print("up axis:     {}{}{}\n", up_axis_name(motion.up_axis),
             motion.up_source.empty() ? "" : ", " + motion.up_source,
             motion.up_axis == UpAxis::kPosY ? "" : " (turned to +Y for following)");
  if (!motion.up_warning.empty()) fmt::print("             {}\n", motion.up_warning);
  if (body.valid()) {
    fmt::print("height:      {:.2f} m estimated (legs {:.2f} m, arms {:.2f} m, trunk {:.2f} m)\n",
               body.standing_height_m, body.leg_length_m, body.arm_length_m,
               body.trunk_length_m);
  } else if (is_head_hands_input(motion.roles)) {
    double head_high = 0.0;
    for (int f = 0; f < clip.frame_count(); ++f) {
      head_high = std::max(head_high, clip.translations_ls(f)[kPointsHead].y());
    }
    fmt::print("height:      head up to {:.2f} m above the floor (three points: head and hands)\n",
               head_high);
  } else {
    fmt::print("height:      unknown (needs the roles)\n");
  }
  fmt::print("joints:      {} (+{} end sites)\n", skeleton.animated_joint_count(),
             skeleton.joint_count() - skeleton.animated_joint_count());
  fmt::print("channels:    {}\n", skeleton.channel_count());
  fmt::print("frames:      {}\n", clip.frame_count());
  fmt::print("fps:         {:.6g}\n", clip.frame_rate());
  fmt::print("duration:    {:.3f} s\n", clip.duration());
  fmt::print("extent (m):  x [{:.3f}, {:.3f}]  y [{:.3f}, {:.3f}]  z [{:.3f}, {:.3f}]\n", low.x(),
             high.x(), low.y(), high.y(), low.z(), high.z());
  fmt::print("roles ({}):\n", motion.roles.convention == "names"       ? "from the joint names"
                              : motion.roles.convention == "hierarchy" ? "from the hierarchy"
                              : motion.roles.convention == "none"      ? "not found"
                                                                       : motion.roles.convention);
  for (int r = 0; r < kRoleCount; ++r) {
    const int joint = motion.roles.joints[static_cast<std::size_t>(r)];
    fmt::print("  {:<15} {:<16} {}\n", role_name(static_cast<Role>(r)),
               joint_name(skeleton, joint), motion.role_detection.notes[static_cast<std::size_t>(r)]);
  }
  if (full_body_roles) {
    fmt::print("rest pose:   {}\n",
               rest_pose_stands(skeleton, motion.roles)
                   ? "a standing body"
                   : "no standing body: where the head faces (three points, retargeting) is read "
                     "from the motion");
  }
  if (calibration && static_cast<bool>(*calibration)) {
    const ArmsForward& arms = calibration->value();
    fmt::print(
        "calibration: a body calibration's pose (--calibration): head {:.2f} m high, wrists held "
        "{:.2f} m apart and {:.2f} m in front of the head\n",
        pose_head_m, (arms.wrists[0].x() - arms.wrists[1].x()) * pose_head_m,
        0.5 * (arms.wrists[0].z() + arms.wrists[1].z()) * pose_head_m);
  } else if (calibration) {
    fmt::print("calibration: not a body calibration's pose: {}\n", calibration->error().message);
  }
  if (problems.empty() && is_head_hands_input(motion.roles)) {
    fmt::print("follower:    this file can drive the three-point follower (head and hands)\n");
  } else if (problems.empty()) {
    fmt::print("follower:    this file can drive the follower\n");
  } else {
    fmt::print("follower:    this file cannot drive the follower:\n");
    for (const std::string& p : problems) fmt::print("  - {}\n", p);
    if (!motion.role_detection.complete()) {
      fmt::print("why:         {}\n", motion.role_detection.problem);
    }
  }
  return kExitOk;
}

}  // namespace

Command register_inspect(CLI::App& app) {
  auto args = std::make_shared<InspectArgs>();
  app.footer(
      "Prints joints, frames, frame rate, units and how they were decided, the estimated body "
      "height, whether the rest pose is a standing body, each role's joint and how it was found "
      "(built-in map, joint names or hierarchy), and "
      "whether the file can drive the follower (and why not); for three points, whether it holds a "
      "body calibration's pose (--calibration). Exits 0 even when roles are "
      "missing.");
  app.add_option("files", args->files, "A .bvh file, or an .asf and an .amc file")
      ->required()
      ->expected(1, 2)
      ->check(CLI::ExistingFile);
  add_motion_file_options(app, args->motion);
  app.add_flag("--json", args->json, "Print one JSON object instead of text");
  return [args] { return run_inspect(*args); };
}

}  // namespace duet::app
