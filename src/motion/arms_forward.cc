#include "duet/motion/arms_forward.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "duet/math/median.h"
#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"

namespace duet {

namespace {

// Per side and coordinate, the values of the frames seen; the median of each makes the result.
struct WristSamples {
  std::array<std::array<std::vector<double>, 3>, 2> coordinates;

  void add(int side, const Vec3& v) {
    for (int k = 0; k < 3; ++k) {
      coordinates[static_cast<std::size_t>(side)][static_cast<std::size_t>(k)].push_back(v[k]);
    }
  }
  bool empty() const { return coordinates[0][0].empty(); }
  ArmsForward medians(double per_unit) {
    ArmsForward pose;
    for (std::size_t side = 0; side < 2; ++side) {
      for (std::size_t k = 0; k < 3; ++k) {
        pose.wrists[side][static_cast<int>(k)] =
            upper_median(std::move(coordinates[side][k])) * per_unit;
      }
    }
    return pose;
  }
};

// A point relative to the head, in the head's heading frame.
Vec3 in_head_frame(const Vec3& point, const Vec3& head, const Quat& head_canonical) {
  return yaw_rotation(-heading_yaw(head_canonical)) * (point - head);
}

}  // namespace

std::string ArmsForward::check() const {
  const Vec3& left = wrists[0];
  const Vec3& right = wrists[1];
  if (!left.allFinite() || !right.allFinite()) return "the wrists' places are not numbers";
  for (const Vec3* wrist : {&left, &right}) {
    const char* side = wrist == &left ? "left" : "right";
    if (!((*wrist).z() >= 0.15 && (*wrist).z() <= 1.0)) {
      return fmt::format("the {} wrist is {:.2f} head heights in front of the head, not 0.15-1",
                         side, (*wrist).z());
    }
    if (!((*wrist).y() >= -0.6 && (*wrist).y() <= 0.3)) {
      return fmt::format(
          "the {} wrist is {:.2f} head heights above the head, not between -0.6 and 0.3", side,
          (*wrist).y());
    }
  }
  const double apart = left.x() - right.x();
  if (!(apart > 0.0 && apart <= 0.7)) {
    return fmt::format("the wrists are {:.2f} head heights apart left to right, not 0-0.7", apart);
  }
  return {};
}

Result<ArmsForward> arms_forward_of_body(const Clip& full_body, const JointRoles& roles,
                                         int stride) {
  Result<Quat> correction = head_correction(full_body, roles);
  if (!correction) return correction.error();
  return arms_forward_of_body(full_body, roles, correction.value(), stride);
}

Result<ArmsForward> arms_forward_of_body(const Clip& full_body, const JointRoles& roles,
                                         const Quat& correction, int stride) {
  const int head = roles[Role::kHead];
  const std::array<std::array<Role, 3>, 2> arms = {
      {{Role::kLeftShoulder, Role::kLeftElbow, Role::kLeftWrist},
       {Role::kRightShoulder, Role::kRightElbow, Role::kRightWrist}}};
  for (const auto& arm : arms) {
    for (Role role : arm) {
      if (roles[role] < 0 || roles[role] >= full_body.joint_count() || head < 0) {
        return Error{"arms held forward: the rig needs a head, shoulders, elbows and wrists"};
      }
    }
  }
  const auto n = static_cast<std::size_t>(full_body.joint_count());
  std::vector<Vec3> positions(n);
  std::vector<Quat> rotations(n);
  WristSamples samples;
  std::array<std::vector<double>, 2> arm_lengths;
  const auto at = [&](Role role) { return positions[static_cast<std::size_t>(roles[role])]; };
  for (int f = 0; f < full_body.frame_count(); f += std::max(1, stride)) {
    forward_kinematics(full_body.skeleton(), full_body.translations_ls(f),
                       full_body.rotations_ls(f), positions, rotations);
    const Vec3 head_ws = positions[static_cast<std::size_t>(head)];
    const Quat head_canonical = rotations[static_cast<std::size_t>(head)] * correction;
    if (!head_ws.allFinite() || !head_canonical.coeffs().allFinite()) continue;
    for (std::size_t side = 0; side < 2; ++side) {
      const auto& [shoulder, elbow, wrist] = arms[side];
      samples.add(static_cast<int>(side), in_head_frame(at(shoulder), head_ws, head_canonical));
      arm_lengths[side].push_back((at(elbow) - at(shoulder)).norm() +
                                  (at(wrist) - at(elbow)).norm());
    }
  }
  if (samples.empty()) return Error{"arms held forward: no frame of the motion is finite"};
  const double head_height_m = highest_head_m(full_body, roles);
  if (!(head_height_m > 0.0)) return Error{"arms held forward: the head is never above the floor"};
  ArmsForward pose = samples.medians(1.0 / head_height_m);
  for (std::size_t side = 0; side < 2; ++side) {
    pose.wrists[side].z() += upper_median(std::move(arm_lengths[side])) / head_height_m;
  }
  return pose;
}

double median_head_height(const Clip& points) {
  if (points.joint_count() != kHeadHandsJointCount) return 0.0;
  const auto n = static_cast<std::size_t>(points.joint_count());
  std::vector<Vec3> positions(n);
  std::vector<Quat> rotations(n);
  std::vector<double> heights;
  for (int f = 0; f < points.frame_count(); ++f) {
    forward_kinematics(points.skeleton(), points.translations_ls(f), points.rotations_ls(f),
                       positions, rotations);
    if (std::isfinite(positions[kPointsHead].y())) heights.push_back(positions[kPointsHead].y());
  }
  return upper_median(std::move(heights));
}

ArmsForward median_arms_forward(std::span<const ArmsForward> poses) {
  WristSamples samples;
  for (const ArmsForward& pose : poses) {
    for (int side = 0; side < 2; ++side)
      samples.add(side, pose.wrists[static_cast<std::size_t>(side)]);
  }
  return samples.empty() ? ArmsForward{} : samples.medians(1.0);
}

Result<ArmsForward> arms_forward_of_points(const Clip& points, double head_height) {
  if (points.joint_count() != kHeadHandsJointCount) {
    return Error{"arms held forward: three points (a head and two hands) are needed"};
  }
  const auto n = static_cast<std::size_t>(points.joint_count());
  std::vector<Vec3> positions(n);
  std::vector<Quat> rotations(n);
  WristSamples samples;
  const Quat correction = head_hands_device_correction();
  for (int f = 0; f < points.frame_count(); ++f) {
    forward_kinematics(points.skeleton(), points.translations_ls(f), points.rotations_ls(f),
                       positions, rotations);
    const Vec3 head = positions[kPointsHead];
    const Quat head_canonical = rotations[kPointsHead] * correction;
    const Vec3 left = in_head_frame(positions[kPointsLeftHand], head, head_canonical);
    const Vec3 right = in_head_frame(positions[kPointsRightHand], head, head_canonical);
    if (!head.allFinite() || !left.allFinite() || !right.allFinite()) continue;
    samples.add(0, left);
    samples.add(1, right);
  }
  if (samples.empty()) return Error{"arms held forward: no frame of the points is finite"};
  const double unit = head_height > 0.0 ? head_height : median_head_height(points);
  if (!(unit > 0.0)) return Error{"arms held forward: the head is not above the floor"};
  ArmsForward pose = samples.medians(1.0 / unit);
  if (std::string problem = pose.check(); !problem.empty()) {
    return Error{"arms held forward: " + problem +
                 " (stand straight with both arms held straight forward, level with the "
                 "shoulders)"};
  }
  return pose;
}

}  // namespace duet
