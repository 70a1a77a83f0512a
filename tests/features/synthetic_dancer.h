// A small synthetic dancer for feature tests: a skeleton with every role of the "daz" map and a
// smooth, non-repeating motion.
#pragma once

#include <cmath>
#include <memory>

#include "duet/math/rotation.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"

namespace duet::testing {

inline std::shared_ptr<Skeleton> make_role_skeleton() {
  auto s = std::make_shared<Skeleton>();
  const auto& names = builtin_skeleton_maps()[0].joint_names;  // daz
  // Role order: hips, spine, chest, neck, head, l shoulder/elbow/wrist, r ..., l hip/knee/ankle/
  // toe, r ...; parents chosen to form a body.
  const int parents[kRoleCount] = {-1, 0, 1, 2, 3, 2, 5, 6, 2, 8, 9, 0, 11, 12, 13, 0, 15, 16, 17};
  const Vec3 offsets[kRoleCount] = {
      {0, 0.9, 0},     {0, 0.1, 0},      {0, 0.2, 0},     {0, 0.25, 0},   {0, 0.1, 0},
      {0.2, 0.05, 0},  {0.28, 0, 0},     {0.25, 0, 0},    {-0.2, 0.05, 0}, {-0.28, 0, 0},
      {-0.25, 0, 0},   {0.1, -0.05, 0},  {0, -0.42, 0},   {0, -0.42, 0},  {0, -0.05, 0.12},
      {-0.1, -0.05, 0}, {0, -0.42, 0},   {0, -0.42, 0},   {0, -0.05, 0.12}};
  for (int r = 0; r < kRoleCount; ++r) {
    Joint j;
    j.name = names[static_cast<std::size_t>(r)];
    j.parent = parents[r];
    j.offset = offsets[r];
    j.channels = r == 0 ? std::vector<Channel>{Channel::kXposition, Channel::kYposition,
                                                Channel::kZposition, Channel::kZrotation,
                                                Channel::kXrotation, Channel::kYrotation}
                        : std::vector<Channel>{Channel::kZrotation, Channel::kXrotation,
                                               Channel::kYrotation};
    j.end_site = r == static_cast<int>(Role::kLeftToe) || r == static_cast<int>(Role::kRightToe);
    if (j.end_site) j.channels.clear();
    s->joints.push_back(j);
  }
  return s;
}

// Every joint swings on its own incommensurate frequencies; the root walks a curve and turns.
inline Clip make_dance(std::shared_ptr<const Skeleton> skeleton, double fps, int frames) {
  Clip clip(skeleton, fps, frames);
  for (int f = 0; f < frames; ++f) {
    const double t = f / fps;
    auto rotations = clip.rotations_ls(f);
    for (int j = 0; j < clip.joint_count(); ++j) {
      if (skeleton->joints[static_cast<std::size_t>(j)].end_site) continue;
      const double a = 0.7 + 0.13 * j, b = 1.1 + 0.07 * j;
      rotations[static_cast<std::size_t>(j)] = exp_map(
          Vec3(0.4 * std::sin(a * t + j), 0.3 * std::sin(b * t), 0.25 * std::cos(0.5 * a * t)));
    }
    rotations[0] = yaw_rotation(0.4 * t) * rotations[0];
    clip.translations_ls(f)[0] = Vec3(std::sin(0.3 * t), 0.9 + 0.02 * std::sin(3 * t), 0.5 * t);
  }
  return clip;
}

inline JointRoles daz_roles(const Skeleton& skeleton) {
  JointRoles roles;
  std::string missing;
  resolve_roles(skeleton, builtin_skeleton_maps()[0], roles, missing);
  return roles;
}

}  // namespace duet::testing
