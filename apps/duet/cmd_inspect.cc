// duet inspect FILE.bvh | SKELETON.asf MOTION.amc [--json]
#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "duet/io/motion_file.h"
#include "duet/motion/forward_kinematics.h"
#include "motion_options.h"

namespace duet::app {

namespace {

struct InspectArgs {
  std::vector<std::string> files;
  MotionFileOptions motion;
  bool json = false;
};

int run_inspect(const InspectArgs& args) {
  MotionLoadOptions load_options;
  if (!make_load_options(args.motion, load_options)) return kExitFailure;
  Result<LoadedMotion> loaded = load_motion(args.files, load_options);
  if (!loaded) {
    fmt::print(stderr, "duet inspect: {}\n", loaded.error().message);
    return kExitFailure;
  }
  const Clip& clip = loaded.value().clip;
  const Skeleton& skeleton = clip.skeleton();

  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 high = -low;
  const std::vector<Vec3> positions = world_positions(clip);
  for (const Vec3& p : positions) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  if (positions.empty()) low = high = Vec3::Zero();

  if (args.json) {
    nlohmann::json doc;
    doc["file"] = loaded.value().description;
    doc["joints"] = skeleton.animated_joint_count();
    doc["end_sites"] = skeleton.joint_count() - skeleton.animated_joint_count();
    doc["frames"] = clip.frame_count();
    doc["fps"] = clip.frame_rate();
    doc["duration_s"] = clip.duration();
    doc["channels"] = skeleton.channel_count();
    doc["convention"] = loaded.value().roles.convention;
    doc["metres_per_unit"] = loaded.value().metres_per_unit;
    doc["bounding_box_m"] = {{"min", {low.x(), low.y(), low.z()}},
                             {"max", {high.x(), high.y(), high.z()}}};
    nlohmann::json names = nlohmann::json::array();
    for (const Joint& j : skeleton.joints) {
      if (!j.end_site) names.push_back(j.name);
    }
    doc["joint_names"] = names;
    std::cout << doc.dump(2) << "\n";
    return kExitOk;
  }
  fmt::print("file:        {}\n", loaded.value().description);
  fmt::print("convention:  {} ({:.6g} m per file unit)\n", loaded.value().roles.convention,
             loaded.value().metres_per_unit);
  fmt::print("joints:      {} (+{} end sites)\n", skeleton.animated_joint_count(),
             skeleton.joint_count() - skeleton.animated_joint_count());
  fmt::print("channels:    {}\n", skeleton.channel_count());
  fmt::print("frames:      {}\n", clip.frame_count());
  fmt::print("fps:         {:.6g}\n", clip.frame_rate());
  fmt::print("duration:    {:.3f} s\n", clip.duration());
  fmt::print("extent (m):  x [{:.3f}, {:.3f}]  y [{:.3f}, {:.3f}]  z [{:.3f}, {:.3f}]\n", low.x(),
             high.x(), low.y(), high.y(), low.z(), high.z());
  fmt::print("roles:      ");
  for (int r = 0; r < kRoleCount; ++r) {
    const int joint = loaded.value().roles.joints[static_cast<std::size_t>(r)];
    fmt::print(" {}={}", role_name(static_cast<Role>(r)),
               skeleton.joints[static_cast<std::size_t>(joint)].name);
  }
  fmt::print("\n");
  return kExitOk;
}

}  // namespace

Command register_inspect(CLI::App& app) {
  auto args = std::make_shared<InspectArgs>();
  app.add_option("files", args->files, "A .bvh file, or an .asf and an .amc file")
      ->required()
      ->expected(1, 2)
      ->check(CLI::ExistingFile);
  add_motion_file_options(app, args->motion);
  app.add_flag("--json", args->json, "Print one JSON object instead of text");
  return [args] { return run_inspect(*args); };
}

}  // namespace duet::app
