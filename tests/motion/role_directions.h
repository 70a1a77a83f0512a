// The role bones' directions of two clips of one motion, compared frame by frame: what the
// retargeting tests hold to 2 degrees (retarget_test.cc, generic_rigs_test.cc).
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "duet/math/rotation.h"
#include "duet/motion/body_space.h"
#include "duet/motion/clip.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/skeleton_map.h"

namespace duet::test {

// The bones the tests compare: upper arms, forearms, thighs, shins, feet, the neck, and the trunk
// as pelvis centre -> neck (and, asked for, pelvis centre -> head). Rigs put their spine joint at
// other heights of the trunk (the salsa rig's at 64 % of the way to the chest, a game avatar's at
// 85 %), so spine -> chest is no one body segment on two rigs; the retargeter keeps the trunk's
// shape (each rig's spine and chest where they sit along it) rather than that bone.
struct Bone {
  Role from, to;
};
inline constexpr Bone kLimbs[] = {
    {Role::kLeftShoulder, Role::kLeftElbow},
    {Role::kLeftElbow, Role::kLeftWrist},
    {Role::kRightShoulder, Role::kRightElbow},
    {Role::kRightElbow, Role::kRightWrist},
    {Role::kLeftHip, Role::kLeftKnee},
    {Role::kLeftKnee, Role::kLeftAnkle},
    {Role::kRightHip, Role::kRightKnee},
    {Role::kRightKnee, Role::kRightAnkle},
    {Role::kNeck, Role::kHead},
    {Role::kLeftAnkle, Role::kLeftToe},
    {Role::kRightAnkle, Role::kRightToe},
};

inline double angle_deg(const Vec3& a, const Vec3& b) {
  return rad_to_deg(std::atan2(a.cross(b).norm(), a.dot(b)));
}

struct Stats {
  double max = 0.0, median = 0.0;
};
inline Stats stats(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return {v.back(), v[v.size() / 2]};
}

// Per frame, the largest angle between the two clips' role bones and pelvis-centre -> neck lines
// (and, with `pelvis_to_head`, their pelvis-centre -> head lines).
inline std::vector<double> direction_errors(const Clip& a, const JointRoles& ra, const Clip& b,
                                            const JointRoles& rb, bool pelvis_to_head) {
  const std::vector<Vec3> pa = world_positions(a), pb = world_positions(b);
  const auto na = static_cast<std::size_t>(a.joint_count()),
             nb = static_cast<std::size_t>(b.joint_count());
  std::vector<double> errors;
  for (int f = 0; f < a.frame_count(); ++f) {
    const std::span<const Vec3> fa(pa.data() + static_cast<std::size_t>(f) * na, na);
    const std::span<const Vec3> fb(pb.data() + static_cast<std::size_t>(f) * nb, nb);
    auto at = [](std::span<const Vec3> p, const JointRoles& r, Role role) {
      return p[static_cast<std::size_t>(r[role])];
    };
    double worst = 0.0;
    for (const Bone& bone : kLimbs) {
      worst = std::max(worst, angle_deg(at(fa, ra, bone.to) - at(fa, ra, bone.from),
                                        at(fb, rb, bone.to) - at(fb, rb, bone.from)));
    }
    worst = std::max(worst, angle_deg(at(fa, ra, Role::kNeck) - pelvis_centre(fa, ra),
                                      at(fb, rb, Role::kNeck) - pelvis_centre(fb, rb)));
    if (pelvis_to_head) {
      worst = std::max(worst, angle_deg(at(fa, ra, Role::kHead) - pelvis_centre(fa, ra),
                                        at(fb, rb, Role::kHead) - pelvis_centre(fb, rb)));
    }
    errors.push_back(worst);
  }
  return errors;
}

}  // namespace duet::test
