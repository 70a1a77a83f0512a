// Automatic rig understanding (issue 10): finds the joint of every role on a skeleton that no
// built-in map names, first from the joint names (Mixamo, Unity/VMC, Perception Neuron, SMPL,
// Rigify, UE, 3ds Max Biped, Bandai, ... spellings), then, where the names say nothing, from the
// hierarchy and the rest pose alone. docs/skeleton-maps.md describes the rules.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "duet/motion/skeleton.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

// How the roles of one skeleton were found, role by role.
struct RoleDetection {
  // `roles.convention` says how: a built-in map's name, "names" or "hierarchy". Roles that were
  // not found hold -1.
  JointRoles roles;
  std::array<std::string, kRoleCount> notes;  // per role: why this joint, or why none
  std::string problem;  // empty when every role was found; else what is missing and why

  bool complete() const { return problem.empty(); }
  std::vector<Role> missing_roles() const;  // the roles that hold -1
};

// The whole detection order: the built-in maps (exact names), then the joint names, then the
// hierarchy. Never fails outright: an incomplete result says what is missing in `problem`.
RoleDetection detect_roles_report(const Skeleton& skeleton);

// Role detection from the joint names alone (case, separators, prefixes such as "mixamorig:",
// side markers). Limbs are found by their distal joints (forearm/elbow, hand/wrist, shin/knee,
// foot/ankle); the upper arm and the thigh are the joints above the elbow and the knee, so
// "shoulder" meaning the clavicle (Unity, Mixamo, Neuron) or the upper arm (SMPL) does not matter.
RoleDetection detect_roles_by_name(const Skeleton& skeleton);

// Role detection from the hierarchy and the rest pose (Y up) for skeletons whose names say
// nothing (j0, j1, ...): the hips are where two legs and the spine branch, the chest where two
// arms and the neck branch; a leg's thigh and shin are its two longest consecutive bones; a hand
// is where the fingers branch (or the last joint of the arm); left is up x forward, forward being
// where the toes point.
RoleDetection detect_roles_by_hierarchy(const Skeleton& skeleton);

}  // namespace duet
