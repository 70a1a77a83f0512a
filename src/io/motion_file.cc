#include "duet/io/motion_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>

#include "duet/io/asf_amc.h"
#include "duet/io/bvh.h"
#include "duet/io/points_csv.h"
#include "duet/motion/head_hands.h"

namespace duet {

namespace {

// Standing heights (metres) a captured adult can have; the unit guess and the warnings use it.
constexpr std::array<double, 2> kPlausibleHeightM = {0.9, 2.3};

std::string lowercase_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::ranges::transform(ext, ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// How the units of a file with no --scale are decided (a BVH; an ASF states its own).
struct UnitsDecision {
  double metres_per_unit = 1.0;
  std::string source, name, warning;  // as in LoadedMotion
};

// `height_in_file_units` is read only when the roles are complete.
UnitsDecision decide_units(const RoleDetection& detection, double height_in_file_units) {
  UnitsDecision units;
  const std::string& convention = detection.roles.convention;
  if (const std::optional<double> known = known_metres_per_unit(convention)) {
    units.metres_per_unit = *known;
    units.source = "convention " + convention;
  } else if (detection.complete()) {
    const UnitGuess guess = guess_units_from_height(height_in_file_units);
    units.metres_per_unit = guess.metres_per_unit;
    units.name = guess.name;
    units.warning = guess.warning;
    units.source = guess.warning.empty() ? "guessed from height" : "default (metres)";
  } else {
    units.name = "metres";
    units.source = "default (metres)";
    units.warning = "cannot guess the units without the body's roles; kept metres";
  }
  return units;
}

}  // namespace

std::optional<double> known_metres_per_unit(const std::string& convention) {
  if (convention == "daz") return 1.0 / 0.768;
  if (convention == "cmu-bvh" || convention == "cmu-asf") return 0.0254 / 0.45;
  return std::nullopt;
}

double default_metres_per_unit(const std::string& convention) {
  return known_metres_per_unit(convention).value_or(1.0);
}

UnitGuess guess_units_from_height(double height_in_file_units) {
  struct Unit {
    const char* name;
    double metres;
  };
  static constexpr std::array<Unit, 5> kUnits = {{{"metres", 1.0},
                                                   {"centimetres", 0.01},
                                                   {"millimetres", 0.001},
                                                   {"inches", 0.0254},
                                                   {"CMU units", 0.0254 / 0.45}}};
  UnitGuess guess{1.0, "metres", ""};
  if (!(height_in_file_units > 0.0) || !std::isfinite(height_in_file_units)) {
    guess.warning = "cannot guess the units: the body has no height";
    return guess;
  }
  double best = std::numeric_limits<double>::infinity();
  for (const Unit& unit : kUnits) {
    const double height = height_in_file_units * unit.metres;
    if (height < kPlausibleHeightM[0] || height > kPlausibleHeightM[1]) continue;
    // Closest in ratio: 1.53 m and 1.89 m are equally far from 1.7 m.
    const double distance = std::abs(std::log(height / 1.7));
    if (distance < best) {
      best = distance;
      guess.metres_per_unit = unit.metres;
      guess.name = unit.name;
    }
  }
  if (!std::isfinite(best)) {
    guess.warning = fmt::format(
        "cannot guess the units: the body is {:.4g} file units tall, an implausible adult "
        "height ({}-{} m) in metres, centimetres, millimetres, inches and CMU units; kept "
        "metres (give --scale)",
        height_in_file_units, kPlausibleHeightM[0], kPlausibleHeightM[1]);
  }
  return guess;
}

double metres_per_unit_read_back(const Skeleton& skeleton, double metres_per_unit) {
  const RoleDetection detection = detect_roles_report(skeleton);
  const double height_in_file_units =
      detection.complete()
          ? measure_body(skeleton, detection.roles, 1.0 / metres_per_unit).standing_height_m
          : 0.0;
  return decide_units(detection, height_in_file_units).metres_per_unit;
}

double readable_metres_per_unit(const Skeleton& skeleton, double preferred) {
  const auto reads_back = [&](double metres_per_unit) {
    const double back = metres_per_unit_read_back(skeleton, metres_per_unit);
    return std::abs(back - metres_per_unit) <= 1e-9 * metres_per_unit;
  };
  if (preferred > 0.0 && std::isfinite(preferred) && reads_back(preferred)) return preferred;
  const RoleDetection detection = detect_roles_report(skeleton);
  if (const std::optional<double> known = known_metres_per_unit(detection.roles.convention)) {
    return *known;  // the reader always assumes these for this convention
  }
  // Metres: the height guess recognises an adult in metres, and keeps metres when it cannot guess.
  return 1.0;
}

namespace {

void decide_up_axis(const MotionLoadOptions& options, bool have_roles, LoadedMotion& loaded);

// A three-point recording (duet/io/points_csv.h): in metres by definition, with its own roles.
Result<LoadedMotion> load_points_csv(const std::string& path, const MotionLoadOptions& options) {
  if (options.map) return Error{path + ": a three-point CSV takes no skeleton map"};
  PointsCsvReadOptions csv;
  csv.frame_rate = options.frame_rate;
  Result<Clip> clip = read_points_csv(path, csv);
  if (!clip) return clip.error();
  LoadedMotion loaded;
  loaded.clip = std::move(clip).value();
  if (options.metres_per_unit) {
    loaded.metres_per_unit = *options.metres_per_unit;
    loaded.clip.scale_lengths(loaded.metres_per_unit);
    loaded.units_source = "given (--scale)";
  } else {
    loaded.units_source = "three-point CSV (metres)";
    loaded.units_name = "metres";
  }
  loaded.roles = head_hands_roles();
  decide_up_axis(options, false, loaded);
  loaded.role_detection.roles = loaded.roles;
  for (Role role : {Role::kHead, Role::kLeftWrist, Role::kRightWrist}) {
    loaded.role_detection.notes[static_cast<std::size_t>(role)] = "three-point CSV column";
  }
  loaded.description = path;
  return loaded;
}

// The file's up axis: given, else read from the body (a three-point recording's is +Y by its
// format), and a tilted world levelled; the clip is turned to Y-up.
void decide_up_axis(const MotionLoadOptions& options, bool have_roles, LoadedMotion& loaded) {
  if (options.up_axis) {
    loaded.up_axis = *options.up_axis;
    loaded.up_source = kUpAxisGiven;
  } else if (is_head_hands_input(loaded.roles)) {
    // No feet: a tilted world (a camera-based tracker) is levelled from the head's path.
    loaded.up_source = "the three-point format's";
    loaded.level = head_path_levelling(loaded.clip, kPointsHead);
    if (loaded.tilt_deg() > 0.0) {
      loaded.up_source += fmt::format(
          "; a tilted floor read from the head's path, levelled by "
          "{:.1f} degrees",
          loaded.tilt_deg());
    }
  } else if (have_roles) {
    const UpAxisDetection detection = detect_up_axis(loaded.clip, loaded.roles);
    if (detection.problem.empty()) {
      loaded.up_axis = detection.axis;
      loaded.up_source = "read from the body";
      loaded.level = levelling_rotation(detection);
      if (loaded.tilt_deg() > 0.0) {
        loaded.up_source +=
            fmt::format("; a tilted floor, levelled by {:.1f} degrees", loaded.tilt_deg());
      }
    } else {
      loaded.up_source = "assumed (+Y)";
      loaded.up_warning = detection.problem + "; +Y assumed (--up sets it)";
    }
  } else {
    loaded.up_source = "assumed (+Y)";
  }
  if (options.level) loaded.level = options.level->normalized();
  const Quat turn = loaded.file_to_y_up();
  if (turn.vec().squaredNorm() > 0.0) turn_world(loaded.clip, turn);
}

}  // namespace

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
  } else if (paths.size() == 1 && is_points_csv_path(paths[0])) {
    return load_points_csv(paths[0], options);
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
    return Error{"expected a .bvh file, a three-point .csv file, or an .asf and an .amc file"};
  }

  const Skeleton& skeleton = loaded.clip.skeleton();
  RoleDetection& detection = loaded.role_detection;
  if (options.map) {
    std::string missing;
    detection.roles.joints.fill(-1);
    if (!resolve_roles(skeleton, *options.map, detection.roles, missing)) {
      return Error{loaded.description + ": skeleton map '" + options.map->name +
                   "' does not fit: missing " + missing};
    }
    for (int r = 0; r < kRoleCount; ++r) {
      detection.notes[static_cast<std::size_t>(r)] =
          "map " + options.map->name + ": '" +
          options.map->joint_names[static_cast<std::size_t>(r)] + "'";
    }
  } else {
    detection = detect_roles_report(skeleton);
    if (!detection.complete() && options.require_roles) {
      return Error{loaded.description + ": " + detection.problem};
    }
  }
  loaded.roles = detection.roles;
  const bool have_roles = detection.complete();

  // Units: --scale, else the ASF file's own, else the convention's, else the body's height.
  if (options.metres_per_unit) {
    loaded.units_source = "given (--scale)";
  } else if (lengths_in_metres) {
    loaded.units_source = "ASF file";
  } else {
    UnitsDecision units = decide_units(
        detection, have_roles ? measure_body(skeleton, loaded.roles, 1.0).standing_height_m : 0.0);
    loaded.metres_per_unit = units.metres_per_unit;
    loaded.units_source = std::move(units.source);
    loaded.units_name = std::move(units.name);
    loaded.units_warning = std::move(units.warning);
  }
  if (!lengths_in_metres) {
    if (options.metres_per_unit) loaded.metres_per_unit = *options.metres_per_unit;
    if (!(loaded.metres_per_unit > 0.0) || !std::isfinite(loaded.metres_per_unit)) {
      return Error{"scale must be a positive number of metres per file unit"};
    }
    loaded.clip.scale_lengths(loaded.metres_per_unit);
  }
  decide_up_axis(options, have_roles, loaded);
  if (have_roles) {
    loaded.body = measure_body(loaded.clip.skeleton(), loaded.roles, 1.0);
    const double height = loaded.body.standing_height_m;
    if (loaded.units_warning.empty() &&
        !(height >= kPlausibleHeightM[0] && height <= kPlausibleHeightM[1])) {
      loaded.units_warning = fmt::format(
          "the body is {:.3g} m tall, not a plausible adult height ({}-{} m): are the units "
          "right? (--scale)",
          height, kPlausibleHeightM[0], kPlausibleHeightM[1]);
    }
  }
  return loaded;
}

}  // namespace duet
