// Rigs of our own (issue 10): a skeleton with other proportions and another rest pose, made from a
// real one, for cross-rig tests and the evaluation. Its local rotations for a given pose differ
// from the original's (the rest pose and hence every joint-local frame below a turned joint
// change), so only rig-independent code (roles, world directions) can follow it.
#pragma once

#include <string>
#include <string_view>

#include "duet/motion/skeleton.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

struct RigProportions {
  // Length factors of the bones of each part: arms = every offset below an upper-arm joint,
  // legs = every offset below a thigh joint, trunk = everything else (pelvis, spine, neck, head,
  // clavicles, the hip joints' place).
  double arms = 1.0;
  double legs = 1.0;
  double trunk = 1.0;
  // Rest pose changes, degrees. Each turns a whole subtree about its joint in the rest pose, so
  // the joint-local frames below it turn too (the skeleton keeps identity rest rotations).
  double arms_down_deg = 0.0;   // upper arms lowered from the source's rest (T-pose -> A-pose)
  double legs_apart_deg = 0.0;  // thighs turned outwards
  double trunk_lean_deg = 0.0;  // spine and everything above it leaning forwards
  double toes_out_deg = 0.0;    // feet turned outwards about the vertical

  // The variant the evaluation and the tests use: longer arms in an A-pose, shorter legs apart,
  // a longer leaning trunk, feet turned out.
  static RigProportions evaluation_variant() { return {1.1, 0.92, 1.05, 40.0, 6.0, 8.0, 15.0}; }
};

// The proportioned rig of `skeleton` (in metres; Y up). Joint names, order, parents and channels
// are kept, so `roles` stay valid for it.
Skeleton make_proportioned_rig(const Skeleton& skeleton, const JointRoles& roles,
                               const RigProportions& proportions);

// Parses "arms=1.1,legs=0.92,trunk=1.05,arms_down=40,legs_apart=6,lean=8,toes_out=15" (any subset,
// any order; unnamed keys keep their defaults). False with the reason in `error`.
bool parse_rig_proportions(std::string_view text, RigProportions& proportions, std::string& error);

}  // namespace duet
