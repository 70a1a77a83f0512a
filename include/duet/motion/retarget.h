// Retargeting (issue 10): puts a motion captured on one skeleton onto another skeleton (another
// studio's rig, a user's avatar, a body with other proportions and another rest pose), keeping
// the world directions of the body roles' bones and the feet on the floor. docs/retarget.md has
// the method, its limits and measured numbers.
//
// Method: world-space role directions. Both rigs are read only through their roles
// (skeleton_map.h); joint names, rest poses and joint-local axes never matter. Per frame, with the
// source posed by forward kinematics, every target joint that plays a role gets a world rotation:
//   - a bone joint (spine -> chest, neck -> head, upper arm -> elbow, forearm -> wrist,
//     thigh -> knee, shin -> ankle, foot: ankle -> toe) is turned so that the target bone points
//     along the source bone. Its twist about the bone comes from the source joint through a rest
//     alignment: the rotation taking the target's rest bone direction to the source's (so a
//     T-pose source drives an A-pose target), then the smallest swing makes the direction exact.
//   - the hips and the chest are oriented from two vectors each, the trunk's up (pelvis centre ->
//     spine; chest -> neck) kept exact and the left-right line (right hip -> left hip; right
//     shoulder -> left shoulder) made perpendicular to it, so the body's facing and twist transfer.
//     The rigs need not put their spine and chest joints at the same heights: each follows the
//     point of the source's trunk (pelvis centre -> spine -> chest -> neck) at its own share of
//     its trunk's length, so a bent trunk keeps its shape (taking the source's spine direction for
//     a game avatar's longer lower trunk put its shoulders 20 cm further forward in a deep bend).
//     When a rig's neck joint sits on its chest joint (the CMU MotionBuilder rig) there is no
//     chest up: the chest then turns like a bone whose direction is the shoulder line.
//   - an end joint (head, hands, toes) keeps its rotation relative to its parent role's bone, seen
//     through that bone's rest alignment.
// Joints without a role: one that lies between two roles (a clavicle, a pelvis-to-thigh joint, a
// lower back) takes the local rotation of the joint at the same place on the source's path when
// both rigs have the same number of joints there (seen through the parent role's rest alignment),
// otherwise its rest rotation (identity); the role joints below it then make the directions exact
// either way. Joints off the role paths (fingers, eyes) keep their rest rotation.
//
// Root: the pelvis centre's floor path is the source's scaled by the stride scale (target leg
// length / source leg length, measure_body), so strides fit the new legs. Height: the lowest of the
// target's foot points (ankles, toes) is put at the source's lowest foot point's height times the
// stride scale, every frame. Both lowest points are minima of continuous curves, so the height is
// continuous (no popping); docs/retarget.md gives its measured frame-to-frame change.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

struct RetargetOptions {
  // Scale of the root's path; default: target leg length / source leg length.
  std::optional<double> stride_scale;
  // Put the target's lowest foot point at the source's (scaled) every frame. Off: the pelvis
  // centre's height is the source's times the stride scale.
  bool feet_on_floor = true;
  // Each rig's head correction (head_hands.h, head_correction: the head joint's world rotation
  // times it faces where the body faces). With both, the target's head faces as the source's
  // does, R_target = R_source * source_head_correction * target_head_correction^-1, instead of
  // keeping the source head's turn on its neck through the rest poses' alignment of the neck,
  // which is arbitrary for a rig whose rest pose is no body: take 01 on the Bandai rig had its
  // head 98 degrees off where the Bandai rig's own clips hold theirs. set_head_corrections().
  std::optional<Quat> source_head_correction;
  std::optional<Quat> target_head_correction;
};

// Sets `options`' head corrections when either rig's rest pose does not stand
// (rest_pose_stands), each from that rig's own motion (head_correction; `target_motion` is a clip
// of the target rig, such as the --rig file's). Leaves them unset when both rest poses stand
// (the rest alignment is then exact both ways) or when a rig's motion cannot tell.
void set_head_corrections(RetargetOptions& options, const Clip& source,
                          const JointRoles& source_roles, const Clip& target_motion,
                          const JointRoles& target_roles);

// Built once per pair of rigs (allocates); retarget_frame() then allocates nothing. Not
// thread-safe: it owns scratch buffers, so use one per thread. Both skeletons are in metres.
class Retargeter {
 public:
  // Checks the roles against both skeletons and measures both bodies; an error names which rig
  // and what is wrong (`source_name`/`target_name` are used in the messages, e.g. file names).
  static Result<Retargeter> create(std::shared_ptr<const Skeleton> source,
                                   const JointRoles& source_roles,
                                   std::shared_ptr<const Skeleton> target,
                                   const JointRoles& target_roles,
                                   const RetargetOptions& options = {},
                                   const std::string& source_name = "source",
                                   const std::string& target_name = "target");

  // One frame: source local pose in, target local pose out (every span sized to its skeleton's
  // joint count). Non-root target translations are the target's rest offsets.
  void retarget_frame(std::span<const Vec3> source_translations_ls,
                      std::span<const Quat> source_rotations_ls,
                      std::span<Vec3> target_translations_ls, std::span<Quat> target_rotations_ls);

  double stride_scale() const { return stride_scale_; }
  const Skeleton& target() const { return *target_; }
  std::shared_ptr<const Skeleton> target_ptr() const { return target_; }

  // A point of the source's trunk a target joint follows: a weighted sum of source role joints.
  struct TrunkPoint {
    std::array<int, 3> joints = {-1, -1, -1};
    std::array<double, 3> weights = {0.0, 0.0, 0.0};
  };
  // JointRule::source_start of the spine bone: it runs from the spine's trunk point to the
  // chest's.
  static constexpr int kTrunkPoints = -2;

  // How a target joint gets its rotation (public for the implementation's helpers only).
  // kFacing: the world rotation of the source joint times the alignment (the head, with
  // RetargetOptions' head corrections).
  enum class Rule : int { kRest, kCopy, kDirection, kFrame, kFollow, kFacing };
  struct JointRule {
    Rule rule = Rule::kRest;
    int source = -1;  // kCopy/kDirection/kFrame/kFollow/kFacing: the source joint it follows
    int target_end = -1;          // kDirection: the target child role joint (bone end)
    int source_end = -1;          // kDirection: the source child role joint
    int parent_role = -1;         // kCopy/kFollow: the target role joint whose alignment applies
    int source_parent_role = -1;  // kFollow: that role's source joint
    Quat alignment = Quat::Identity();  // rest alignment: target rest frame -> source rest frame
    int target_start = -1;  // kDirection: where the bone starts (the joint itself, or the right
    int source_start = -1;  // shoulder for a chest oriented by its shoulder line)
  };

 private:
  Retargeter() = default;

  std::shared_ptr<const Skeleton> source_;
  std::shared_ptr<const Skeleton> target_;
  JointRoles source_roles_;
  JointRoles target_roles_;
  RetargetOptions options_;
  double stride_scale_ = 1.0;
  std::vector<JointRule> rules_;  // per target joint
  TrunkPoint spine_point_;        // where on the source's trunk the target's spine sits
  TrunkPoint chest_point_;        // and its chest
  // Per-frame scratch (sized at creation).
  std::vector<Vec3> source_positions_;
  std::vector<Quat> source_world_;
  std::vector<Vec3> target_positions_;
  std::vector<Quat> target_world_;
};

// The whole clip through one Retargeter; the result has the target skeleton and the source's
// frame rate and frame count. `source_name`/`target_name` name the rigs in error messages.
Result<Clip> retarget_clip(const Clip& source, const JointRoles& source_roles,
                           std::shared_ptr<const Skeleton> target, const JointRoles& target_roles,
                           const RetargetOptions& options = {},
                           const std::string& source_name = "source",
                           const std::string& target_name = "target");

}  // namespace duet
