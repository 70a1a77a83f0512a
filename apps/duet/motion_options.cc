#include "motion_options.h"

#include <fmt/format.h>

#include "number_checks.h"

namespace duet::app {

void add_motion_file_options(CLI::App& app, MotionFileOptions& options, const std::string& prefix) {
  app.add_option("--" + prefix + "fps", options.fps,
                 "Frame rate of the file(s), overriding the header (the CMU salsa BVH headers "
                 "say 120; the takes are 60 Hz); for a three-point CSV, the even grid its "
                 "time_s samples are resampled onto (its times stay)")
      ->check(fps_check());
  app.add_option("--" + prefix + "scale", options.scale,
                 "Metres per file unit (default: known per skeleton convention: salsa DAZ BVH "
                 "1/0.768, CMU 0.056444; otherwise guessed from the body's height: m, cm, mm, "
                 "inches or CMU units)")
      ->check(scale_check());
  app.add_option("--" + prefix + "map", options.map_path,
                 "Skeleton map JSON naming the joint of each role, instead of detecting the roles "
                 "(see docs/skeleton-maps.md)")
      ->check(CLI::ExistingFile);
  app.add_option("--" + prefix + "up", options.up,
                 "The file's up axis: auto (default: read from the body, feet to head; a "
                 "three-point CSV's is +Y), y, z, x, -y, -z or -x. A Z-up file (3ds Max, Motive, "
                 "some Blender exports) is turned to Y-up for following and its outputs are "
                 "written back in its own world; with auto a tilted floor is levelled (read from "
                 "the toes, or a three-point CSV's head path)")
      ->check([](const std::string& text) -> std::string {
        UpAxis axis;
        if (text == "auto" || parse_up_axis(text, axis)) return {};
        return "expected auto, y, z, x, -y, -z or -x, got '" + text + "'";
      });
}

bool make_load_options(const MotionFileOptions& options, MotionLoadOptions& load_options) {
  load_options.frame_rate = options.fps;
  load_options.metres_per_unit = options.scale;
  if (UpAxis axis; !options.up.empty() && options.up != "auto" && parse_up_axis(options.up, axis)) {
    load_options.up_axis = axis;
  }
  if (!options.map_path.empty()) {
    SkeletonMap map;
    std::string error;
    if (!load_skeleton_map(options.map_path, map, error)) {
      fmt::print(stderr, "duet: {}\n", error);
      return false;
    }
    load_options.map = map;
  }
  return true;
}

}  // namespace duet::app
