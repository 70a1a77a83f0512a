// The skeleton a VMC stream drives (Virtual Motion Capture protocol, https://protocol.vmc.info):
// the body bones of Unity's HumanBodyBones (Hips, Spine, Chest, UpperChest, Neck, Head, the
// shoulders, arms, hands, legs, feet and toes; fingers, eyes and jaw are left out: the follower
// reads none of them), with the names VMC sends, in a T-pose whose local rotations are identity
// (a VRM-normalised avatar's rest pose, which VMC rotations are relative to), 1.7 m tall.
//
// Axes: Unity is left-handed (X right, Y up, Z forward); Duet is right-handed, Y up, metres. The
// conversion mirrors X: a position (x, y, z) becomes (-x, y, z), a rotation (x, y, z, w) becomes
// (x, -y, -z, w). The mirror is its own inverse, so the same functions convert back.
#pragma once

#include <string_view>

#include "duet/live/source_frame.h"

namespace duet {

// The VMC humanoid: offsets in metres in Duet's axes (facing +Z, its left hand at +X), roles
// resolved by name, End Sites after the head, hands and toes (for drawing and BVH recordings).
SourceSkeleton vmc_humanoid(double frame_rate = 60.0);

// The joint index of a HumanBodyBones name in vmc_humanoid(), or -1 (a finger, an eye, a name
// VMC does not use). Exact, case-sensitive: VMC sends the enum names as they are.
int vmc_bone_index(std::string_view name) noexcept;

Vec3 unity_to_duet(const Vec3& unity_position) noexcept;
Quat unity_to_duet(const Quat& unity_rotation) noexcept;
inline Vec3 duet_to_unity(const Vec3& p) noexcept { return unity_to_duet(p); }
inline Quat duet_to_unity(const Quat& q) noexcept { return unity_to_duet(q); }

}  // namespace duet
