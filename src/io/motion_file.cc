#include "duet/io/motion_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "duet/io/asf_amc.h"
#include "duet/io/bvh.h"

namespace duet {

namespace {

std::string lowercase_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::ranges::transform(ext, ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

double default_metres_per_unit(const std::string& convention) {
  if (convention == "daz") return 1.0 / 0.768;
  if (convention == "cmu-bvh" || convention == "cmu-asf") return 0.0254 / 0.45;
  return 1.0;
}

Result<LoadedMotion> load_motion(const std::vector<std::string>& paths,
                                 const MotionLoadOptions& options) {
  LoadedMotion loaded;
  bool lengths_in_metres = false;
  if (paths.size() == 1 && lowercase_extension(paths[0]) == ".bvh") {
    BvhReadOptions bvh;
    bvh.frame_rate = options.frame_rate;
    Result<Clip> clip = read_bvh(paths[0], bvh);
    if (!clip) return clip.error();
    loaded.clip = std::move(clip).value();
    loaded.description = paths[0];
  } else if (paths.size() == 2) {
    std::string asf = paths[0], amc = paths[1];
    if (lowercase_extension(asf) == ".amc") std::swap(asf, amc);
    if (lowercase_extension(asf) != ".asf" || lowercase_extension(amc) != ".amc") {
      return Error{"expected one .asf and one .amc file, got '" + paths[0] + "' and '" +
                   paths[1] + "'"};
    }
    AsfAmcReadOptions asf_options;
    if (options.frame_rate) asf_options.frame_rate = *options.frame_rate;
    asf_options.metres_per_unit = options.metres_per_unit;
    Result<Clip> clip = read_asf_amc(asf, amc, asf_options);
    if (!clip) return clip.error();
    loaded.clip = std::move(clip).value();
    loaded.description = asf + " + " + amc;
    lengths_in_metres = true;  // the ASF reader applies the file's own units
  } else {
    return Error{"expected a .bvh file, or an .asf and an .amc file"};
  }

  std::string error;
  if (options.map) {
    if (!resolve_roles(loaded.clip.skeleton(), *options.map, loaded.roles, error)) {
      return Error{loaded.description + ": skeleton map '" + options.map->name +
                   "' does not fit: missing " + error};
    }
  } else if (!detect_roles(loaded.clip.skeleton(), loaded.roles, error)) {
    return Error{loaded.description + ": " + error};
  }

  if (!lengths_in_metres) {
    loaded.metres_per_unit =
        options.metres_per_unit.value_or(default_metres_per_unit(loaded.roles.convention));
    if (!(loaded.metres_per_unit > 0.0) || !std::isfinite(loaded.metres_per_unit)) {
      return Error{"scale must be a positive number of metres per file unit"};
    }
    loaded.clip.scale_lengths(loaded.metres_per_unit);
  }
  return loaded;
}

}  // namespace duet
