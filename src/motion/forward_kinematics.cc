#include "duet/motion/forward_kinematics.h"

#include <cassert>

namespace duet {

void forward_kinematics(const Skeleton& skeleton, std::span<const Vec3> translations_ls,
                        std::span<const Quat> rotations_ls, std::span<Vec3> positions_ws,
                        std::span<Quat> rotations_ws) {
  const std::size_t n = skeleton.joints.size();
  assert(translations_ls.size() == n && rotations_ls.size() == n);
  assert(positions_ws.size() == n && rotations_ws.size() == n);
  // Parents come before children, so one pass in index order suffices.
  for (std::size_t j = 0; j < n; ++j) {
    const int parent = skeleton.joints[j].parent;
    if (parent < 0) {
      positions_ws[j] = translations_ls[j];
      rotations_ws[j] = rotations_ls[j];
    } else {
      const auto p = static_cast<std::size_t>(parent);
      positions_ws[j] = rotations_ws[p] * translations_ls[j] + positions_ws[p];
      rotations_ws[j] = rotations_ws[p] * rotations_ls[j];
    }
  }
}

std::vector<Vec3> world_positions(const Clip& clip) {
  const auto n = static_cast<std::size_t>(clip.joint_count());
  std::vector<Vec3> result(n * static_cast<std::size_t>(clip.frame_count()));
  std::vector<Quat> rotations(n);
  for (int f = 0; f < clip.frame_count(); ++f) {
    forward_kinematics(clip.skeleton(), clip.translations_ls(f), clip.rotations_ls(f),
                       std::span<Vec3>(result.data() + static_cast<std::size_t>(f) * n, n),
                       rotations);
  }
  return result;
}

std::vector<Vec3> rest_positions(const Skeleton& skeleton) {
  const auto n = static_cast<std::size_t>(skeleton.joint_count());
  std::vector<Vec3> offsets(n), positions(n);
  std::vector<Quat> identity(n, Quat::Identity()), world(n);
  for (std::size_t j = 0; j < n; ++j) offsets[j] = skeleton.joints[j].offset;
  forward_kinematics(skeleton, offsets, identity, positions, world);
  return positions;
}

}  // namespace duet
