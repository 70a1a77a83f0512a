// Tiny synthetic fixtures for the partner tests (and the partner benchmark): a humanoid with the
// joint names and layout of the CMU salsa (DAZ) skeleton, 43 animated joints plus End Sites, in
// metres, facing +Z, Y up, standing on y = 0.
#pragma once

#include <cstdlib>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "duet/math/rotation.h"
#include "duet/motion/clip.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/skeleton_map.h"

namespace duet::test {

inline std::shared_ptr<const Skeleton> make_humanoid() {
  auto s = std::make_shared<Skeleton>();
  const auto add = [&](const std::string& name, const std::string& parent, const Vec3& offset) {
    Joint j;
    j.name = name;
    j.parent = parent.empty() ? -1 : s->find(parent);
    j.offset = offset;
    if (parent.empty()) {
      j.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition,
                    Channel::kZrotation, Channel::kYrotation, Channel::kXrotation};
    } else {
      j.channels = {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
    }
    s->joints.push_back(std::move(j));
  };
  const auto end_site = [&](const std::string& parent, const Vec3& offset) {
    Joint j;
    j.name = parent + "_End";
    j.parent = s->find(parent);
    j.offset = offset;
    j.end_site = true;
    s->joints.push_back(std::move(j));
  };
  add("hip", "", Vec3(0, 0.97, 0));
  add("abdomen", "hip", Vec3(0, 0.1, 0));
  add("chest", "abdomen", Vec3(0, 0.2, 0));
  add("neck", "chest", Vec3(0, 0.25, 0));
  add("head", "neck", Vec3(0, 0.1, 0));
  add("leftEye", "head", Vec3(0.03, 0.05, 0.08));
  end_site("leftEye", Vec3(0, 0, 0.02));
  add("rightEye", "head", Vec3(-0.03, 0.05, 0.08));
  end_site("rightEye", Vec3(0, 0, 0.02));
  for (const char side : {'r', 'l'}) {
    const double x = side == 'l' ? 1.0 : -1.0;  // the dancer's left is +X when facing +Z
    const std::string p(1, side);
    add(p + "Collar", "chest", Vec3(0.05 * x, 0.2, 0));
    add(p + "Shldr", p + "Collar", Vec3(0.15 * x, 0, 0));
    add(p + "ForeArm", p + "Shldr", Vec3(0.28 * x, 0, 0));
    add(p + "Hand", p + "ForeArm", Vec3(0.25 * x, 0, 0));
    const char* fingers[] = {"Thumb", "Index", "Mid", "Ring", "Pinky"};
    for (int f = 0; f < 5; ++f) {
      const std::string name = p + fingers[f];
      add(name + "1", p + "Hand", Vec3((f == 0 ? 0.03 : 0.09) * x, 0, 0.03 - 0.015 * f));
      add(name + "2", name + "1", Vec3(0.03 * x, 0, 0));
      end_site(name + "2", Vec3(0.02 * x, 0, 0));
    }
  }
  for (const char side : {'r', 'l'}) {
    const double x = side == 'l' ? 1.0 : -1.0;
    const std::string p(1, side);
    add(p + "Buttock", "hip", Vec3(0.1 * x, 0, 0));
    add(p + "Thigh", p + "Buttock", Vec3(0, -0.05, 0));
    add(p + "Shin", p + "Thigh", Vec3(0, -0.42, 0));
    add(p + "Foot", p + "Shin", Vec3(0, -0.42, 0));
    end_site(p + "Foot", Vec3(0, -0.06, 0.12));
  }
  return s;
}

inline JointRoles humanoid_roles(const Skeleton& skeleton) {
  JointRoles roles;
  std::string error;
  if (!detect_roles(skeleton, roles, error)) std::abort();
  return roles;
}

// A clip of the humanoid standing at the origin facing +Z, arms lowered and elbows bent forwards
// (so the arm chains are not straight).
inline Clip make_standing_clip(const std::shared_ptr<const Skeleton>& skeleton, int frames,
                               double fps = 60.0) {
  Clip clip(skeleton, fps, frames);
  const int ls = skeleton->find("lShldr"), rs = skeleton->find("rShldr");
  const int le = skeleton->find("lForeArm"), re = skeleton->find("rForeArm");
  for (int f = 0; f < frames; ++f) {
    auto r = clip.rotations_ls(f);
    // Upper arms down by 60 degrees, forearms bent forwards.
    r[static_cast<std::size_t>(ls)] = quat_from_axis_angle(Vec3::UnitZ(), deg_to_rad(-60));
    r[static_cast<std::size_t>(rs)] = quat_from_axis_angle(Vec3::UnitZ(), deg_to_rad(60));
    r[static_cast<std::size_t>(le)] = quat_from_axis_angle(Vec3::UnitY(), deg_to_rad(-70));
    r[static_cast<std::size_t>(re)] = quat_from_axis_angle(Vec3::UnitY(), deg_to_rad(70));
  }
  return clip;
}

inline void set_root(Clip& clip, int frame, const Vec3& position, double yaw) {
  clip.translations_ls(frame)[0] = position;
  clip.rotations_ls(frame)[0] = yaw_rotation(yaw);
}

// World positions and rotations of one frame.
struct WorldPose {
  std::vector<Vec3> positions;
  std::vector<Quat> rotations;
};
inline WorldPose world_pose(const Skeleton& skeleton, std::span<const Vec3> translations_ls,
                            std::span<const Quat> rotations_ls) {
  WorldPose w;
  w.positions.resize(skeleton.joints.size());
  w.rotations.resize(skeleton.joints.size());
  forward_kinematics(skeleton, translations_ls, rotations_ls, w.positions, w.rotations);
  return w;
}
inline WorldPose world_pose(const Clip& clip, int frame) {
  return world_pose(clip.skeleton(), clip.translations_ls(frame), clip.rotations_ls(frame));
}

}  // namespace duet::test
