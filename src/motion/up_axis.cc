#include "duet/motion/up_axis.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <vector>

#include "duet/math/rotation.h"
#include "duet/motion/floor_plane.h"
#include "duet/motion/forward_kinematics.h"

namespace duet {
namespace {

struct AxisInfo {
  UpAxis axis;
  std::string_view name;
  Vec3 vector;
};

const std::array<AxisInfo, 6>& axes() {
  static const std::array<AxisInfo, 6> table = {{
      {UpAxis::kPosY, "+Y", Vec3::UnitY()},
      {UpAxis::kNegY, "-Y", -Vec3::UnitY()},
      {UpAxis::kPosZ, "+Z", Vec3::UnitZ()},
      {UpAxis::kNegZ, "-Z", -Vec3::UnitZ()},
      {UpAxis::kPosX, "+X", Vec3::UnitX()},
      {UpAxis::kNegX, "-X", -Vec3::UnitX()},
  }};
  return table;
}

const AxisInfo& info(UpAxis axis) { return axes()[static_cast<std::size_t>(axis)]; }

// Most a dancer's mean feet-to-head direction may lean from the axis it is read as.
constexpr double kMostOffAxisDeg = 35.0;
// Least length of the mean of unit directions: below it the body pointed too many ways.
constexpr double kLeastConsistency = 0.5;

// The head's path (head_path_levelling): drawn towards +Y as the toes' floor is, and levelled
// only when its tilt is this many of its standard errors from level.
constexpr double kHeadPathPriorSigmaDeg = 3.0;
constexpr double kHeadPathSignificance = 3.0;

// The middle of both feet: ankles and toes, or the ankles alone.
Vec3 mid_foot(std::span<const Vec3> positions, const JointRoles& roles, bool with_toes) {
  const auto at = [&](Role role) { return positions[static_cast<std::size_t>(roles[role])]; };
  const Vec3 ankles = 0.5 * (at(Role::kLeftAnkle) + at(Role::kRightAnkle));
  return with_toes ? Vec3(0.5 * ankles + 0.25 * (at(Role::kLeftToe) + at(Role::kRightToe)))
                   : ankles;
}

// Runs visit(positions) on the world positions of up to max_frames frames spread evenly over
// the clip (every frame of a shorter one): what the up axis and the head's path are read from.
template <typename Visit>
void for_each_sampled_pose(const Clip& clip, int max_frames, Visit&& visit) {
  const int joints = clip.joint_count();
  const int samples = std::clamp(clip.frame_count(), 1, std::max(max_frames, 1));
  std::vector<Vec3> positions(static_cast<std::size_t>(joints));
  std::vector<Quat> rotations(static_cast<std::size_t>(joints));
  for (int s = 0; s < samples && s < clip.frame_count(); ++s) {
    const int f = static_cast<int>(static_cast<long long>(s) * clip.frame_count() / samples);
    forward_kinematics(clip.skeleton(), clip.translations_ls(f), clip.rotations_ls(f), positions,
                       rotations);
    visit(std::span<const Vec3>(positions));
  }
}

}  // namespace

std::string_view up_axis_name(UpAxis axis) { return info(axis).name; }

Vec3 up_axis_vector(UpAxis axis) { return info(axis).vector; }

bool parse_up_axis(std::string_view text, UpAxis& axis) {
  std::string t;
  for (const char c : text) t += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (t.size() == 1) t = "+" + t;
  for (const AxisInfo& a : axes()) {
    if (t == a.name) {
      axis = a.axis;
      return true;
    }
  }
  return false;
}

Quat rotation_to_y_up(UpAxis axis) {
  switch (axis) {
    case UpAxis::kPosY:
      return Quat::Identity();
    case UpAxis::kNegY:
      return Quat(Eigen::AngleAxisd(kPi, Vec3::UnitX()));
    case UpAxis::kPosZ:
      return Quat(Eigen::AngleAxisd(-kPi / 2.0, Vec3::UnitX()));
    case UpAxis::kNegZ:
      return Quat(Eigen::AngleAxisd(kPi / 2.0, Vec3::UnitX()));
    case UpAxis::kPosX:
      return Quat(Eigen::AngleAxisd(kPi / 2.0, Vec3::UnitZ()));
    case UpAxis::kNegX:
      return Quat(Eigen::AngleAxisd(-kPi / 2.0, Vec3::UnitZ()));
  }
  return Quat::Identity();
}

UpAxis nearest_axis(const Vec3& direction) {
  const AxisInfo* best = &axes()[0];
  for (const AxisInfo& a : axes()) {
    if (direction.dot(a.vector) > direction.dot(best->vector)) best = &a;
  }
  return best->axis;
}

bool has_feet_and_head(const JointRoles& roles, int joints) {
  for (const Role role : {Role::kHead, Role::kLeftAnkle, Role::kRightAnkle}) {
    if (roles[role] < 0 || roles[role] >= joints) return false;
  }
  return true;
}

Vec3 feet_to_head(std::span<const Vec3> positions, const JointRoles& roles) {
  const Vec3 feet = 0.5 * (positions[static_cast<std::size_t>(roles[Role::kLeftAnkle])] +
                           positions[static_cast<std::size_t>(roles[Role::kRightAnkle])]);
  return positions[static_cast<std::size_t>(roles[Role::kHead])] - feet;
}

UpAxisDetection detect_up_axis(const Clip& clip, const JointRoles& roles, int max_frames) {
  UpAxisDetection result;
  const int joints = clip.joint_count();
  if (!has_feet_and_head(roles, joints)) {
    result.problem = "no head and ankle roles to read the up axis from";
    return result;
  }
  if (clip.frame_count() == 0) {
    result.problem = "no frames to read the up axis from";
    return result;
  }
  const bool with_toes = roles[Role::kLeftToe] >= 0 && roles[Role::kLeftToe] < joints &&
                         roles[Role::kRightToe] >= 0 && roles[Role::kRightToe] < joints;
  Vec3 sum = Vec3::Zero();
  int counted = 0;
  std::vector<std::array<Vec3, 2>> toes;  // the floor's evidence (fit_floor), in the file's world
  const std::array<Role, 2> toe_roles = with_toes ? std::array{Role::kLeftToe, Role::kRightToe}
                                                  : std::array{Role::kLeftAnkle, Role::kRightAnkle};
  for_each_sampled_pose(clip, max_frames, [&](std::span<const Vec3> positions) {
    const Vec3 up = positions[static_cast<std::size_t>(roles[Role::kHead])] -
                    mid_foot(positions, roles, with_toes);
    const double length = up.norm();
    if (!(length > 0.0) || !std::isfinite(length)) return;
    sum += up / length;
    ++counted;
    toes.push_back({positions[static_cast<std::size_t>(roles[toe_roles[0]])],
                    positions[static_cast<std::size_t>(roles[toe_roles[1]])]});
  });
  if (counted == 0) {
    result.problem = "the head and the ankles are at the same place on every frame";
    return result;
  }
  const Vec3 mean = sum / counted;
  if (mean.norm() < kLeastConsistency) {
    result.problem = fmt::format(
        "the body points no consistent way from the feet to the head (mean length {:.2f} of 1)",
        mean.norm());
    return result;
  }
  const Vec3 direction = mean.normalized();
  result.mean_up = direction;
  result.span_s = clip.duration();
  const AxisInfo* best = &info(nearest_axis(direction));
  result.axis = best->axis;
  result.off_axis_deg = rad_to_deg(std::acos(std::clamp(direction.dot(best->vector), -1.0, 1.0)));
  if (result.off_axis_deg > kMostOffAxisDeg) {
    result.problem = fmt::format(
        "the body's feet-to-head direction is {:.0f} degrees from the nearest axis ({}): no up "
        "axis stands out",
        result.off_axis_deg, best->name);
    return result;
  }
  // The floor, in the world turned to Y-up: the lower toe of each sampled frame.
  const Quat to_y_up = rotation_to_y_up(result.axis);
  std::vector<Vec3> floor_points;
  floor_points.reserve(toes.size());
  for (const std::array<Vec3, 2>& pair : toes) {
    const Vec3 a = to_y_up * pair[0];
    const Vec3 b = to_y_up * pair[1];
    floor_points.push_back(a.y() <= b.y() ? a : b);
  }
  result.floor_up = fit_floor(floor_points, to_y_up * direction, result.span_s).up;
  return result;
}

void turn_world(Clip& clip, const Quat& rotation) {
  if (clip.joint_count() == 0) return;
  for (int f = 0; f < clip.frame_count(); ++f) {
    clip.rotations_ls(f)[0] = (rotation * clip.rotations_ls(f)[0]).normalized();
    clip.translations_ls(f)[0] = rotation * clip.translations_ls(f)[0];
  }
}

double tilt_from_vertical_deg(const Vec3& mean_up) {
  const double length = mean_up.norm();
  if (!(length > 0.0) || !std::isfinite(length)) return 0.0;
  return rad_to_deg(std::acos(std::clamp(mean_up.y() / length, -1.0, 1.0)));
}

Quat levelling_rotation(const Vec3& mean_up, double from_deg) {
  const double tilt = tilt_from_vertical_deg(mean_up);
  if (!(tilt > from_deg)) return Quat::Identity();
  return Quat::FromTwoVectors(mean_up.normalized(), Vec3::UnitY()).normalized();
}

Quat levelling_rotation(const UpAxisDetection& detection) {
  if (!detection.problem.empty() || !(detection.span_s >= kLevelLeastSpanS)) {
    return Quat::Identity();
  }
  return levelling_rotation(detection.floor_up);
}

Quat head_path_levelling(const Clip& clip, int head, int max_frames) {
  const int joints = clip.joint_count();
  if (head < 0 || head >= joints || clip.frame_count() == 0 ||
      !(clip.duration() >= kLevelLeastSpanS)) {
    return Quat::Identity();
  }
  std::vector<Vec3> heads;
  for_each_sampled_pose(clip, max_frames, [&](std::span<const Vec3> positions) {
    heads.push_back(positions[static_cast<std::size_t>(head)]);
  });
  const FloorFit path = fit_floor(heads, Vec3::UnitY(), clip.duration(), kHeadPathPriorSigmaDeg,
                                  PlaneOutliers::kBelow);
  // A head's height also changes with the dance (a bend held at one end of the room): a tilt
  // within kHeadPathSignificance standard errors of level is left.
  if (!(tilt_from_vertical_deg(path.up) > kHeadPathSignificance * path.tilt_sigma_deg)) {
    return Quat::Identity();
  }
  return levelling_rotation(path.up);
}

void turn_to_file_world(Clip& clip, const Quat& file_to_y_up) {
  if (file_to_y_up.vec().squaredNorm() > 0.0) turn_world(clip, file_to_y_up.conjugate());
}

}  // namespace duet
