// Rigs of another build than the capture's (issue 10, "their rig is never ours"): skeletons made
// in code the way three common kinds of user rig are built, for the evaluation (`duet eval
// --rigs`) and the tests. Unlike the proportioned rig (rig_variants.h), which keeps the capture's
// joints, these differ in structure: how many spine joints, twist helpers beside the limb joints,
// a root joint on the floor above the pelvis, no clavicles, the toe as the foot's last joint, the
// rest pose's arms, the body's height. Their roles are found by role detection (names), as a
// user's file's would be.
#pragma once

#include <span>
#include <string_view>

#include "duet/base/result.h"
#include "duet/motion/skeleton.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

enum class GenericRig {
  // A game engine's humanoid avatar (Unreal Engine mannequin spellings): a root joint on the
  // floor above the pelvis, five spine joints and two neck joints, twist helpers on the upper
  // arms, forearms and thighs, an A-pose (arms 45 degrees down), 1.80 m.
  kGameAvatar,
  // A depth camera's body tracker (Kinect v2 spellings): three spine joints, no clavicles (the
  // upper arms hang from the top of the spine), hand joints past the wrists, the foot joint as
  // the toe; a T-pose, 1.60 m.
  kDepthCamera,
  // An inertial suit's body (Xsens MVN spellings): four lumbar and thoracic joints between the
  // pelvis and the neck, clavicles, toes; arms 10 degrees below a T-pose, 1.92 m.
  kInertialSuit,
};

struct GenericRigInfo {
  GenericRig rig;
  std::string_view name;  // as `duet eval --rigs` names it
};

// Every generic rig, in the order above.
std::span<const GenericRigInfo> generic_rigs();
// The rig `name` names (GenericRigInfo::name); nullptr for any other name.
const GenericRigInfo* find_generic_rig(std::string_view name);

// The rig's skeleton in metres, Y up, facing +Z, its left towards +X, standing on y = 0 in its
// rest pose (every rotation the identity). The root has position and rotation channels, every
// other joint rotation channels; each leaf ends in an End Site.
Skeleton make_generic_rig(GenericRig rig);

// The rig and the roles role detection finds on it by their names, as a user's file's would be
// read. An error only if detection misses a role (a bug of this file, not the caller's).
struct GenericRigWithRoles {
  Skeleton skeleton;
  JointRoles roles;
};
Result<GenericRigWithRoles> make_generic_rig_with_roles(GenericRig rig);

}  // namespace duet
