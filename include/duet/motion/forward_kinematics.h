// Forward kinematics: local joint transforms -> world (_ws) positions and rotations.
#pragma once

#include <span>
#include <vector>

#include "duet/motion/clip.h"

namespace duet {

// Computes world transforms of every joint. All spans have skeleton.joint_count() elements and
// are owned by the caller; nothing is allocated, so this is safe on the per-frame path.
void forward_kinematics(const Skeleton& skeleton, std::span<const Vec3> translations_ls,
                        std::span<const Quat> rotations_ls, std::span<Vec3> positions_ws,
                        std::span<Quat> rotations_ws);

// World positions of every joint at every frame: result[frame * joint_count + joint].
std::vector<Vec3> world_positions(const Clip& clip);

// World positions of every joint in the rest pose (every rotation the identity, the root at its
// offset). A BVH or ASF rig's joint frames are the world's there.
std::vector<Vec3> rest_positions(const Skeleton& skeleton);

}  // namespace duet
