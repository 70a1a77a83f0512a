#include "duet/motion/retarget.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"

namespace duet {

namespace {

using Rule = Retargeter::Rule;
using JointRule = Retargeter::JointRule;

bool is_ancestor(const Skeleton& skeleton, int ancestor, int joint) {
  for (int j = skeleton.joints[static_cast<std::size_t>(joint)].parent; j >= 0;
       j = skeleton.joints[static_cast<std::size_t>(j)].parent) {
    if (j == ancestor) return true;
  }
  return false;
}

// The joints strictly between `ancestor` and `joint`, top-down.
std::vector<int> joints_between(const Skeleton& skeleton, int ancestor, int joint) {
  std::vector<int> between;
  for (int j = skeleton.joints[static_cast<std::size_t>(joint)].parent; j >= 0 && j != ancestor;
       j = skeleton.joints[static_cast<std::size_t>(j)].parent) {
    between.push_back(j);
  }
  std::reverse(between.begin(), between.end());
  return between;
}

// The vector from `ancestor` to `joint` in the ancestor's frame, through the local transforms of
// the joints in between. Allocation-free; `ancestor` must be an ancestor of `joint` (or equal).
Vec3 chain_vector(const Skeleton& skeleton, int ancestor, int joint,
                  std::span<const Vec3> translations_ls, std::span<const Quat> rotations_ls) {
  if (joint == ancestor) return Vec3::Zero();
  Vec3 v = translations_ls[static_cast<std::size_t>(joint)];
  for (int j = skeleton.joints[static_cast<std::size_t>(joint)].parent; j != ancestor;
       j = skeleton.joints[static_cast<std::size_t>(j)].parent) {
    v = translations_ls[static_cast<std::size_t>(j)] +
        rotations_ls[static_cast<std::size_t>(j)] * v;
  }
  return v;
}

// The rotation whose columns are (left-right, up, forward) of a body part: `up` kept exact,
// `lateral` made perpendicular to it. False when either is degenerate.
bool frame_from(const Vec3& up, const Vec3& lateral, Quat& frame) {
  const double up_norm = up.norm();
  if (!(up_norm > 1e-9)) return false;
  const Vec3 y = up / up_norm;
  const Vec3 x_raw = lateral - lateral.dot(y) * y;
  const double x_norm = x_raw.norm();
  if (!(x_norm > 1e-6 * std::max(1.0, lateral.norm()))) return false;
  const Vec3 x = x_raw / x_norm;
  Eigen::Matrix3d m;
  m.col(0) = x;
  m.col(1) = y;
  m.col(2) = x.cross(y);
  frame = Quat(m);
  return true;
}

// The two vectors of a two-vector (frame) joint, as the endpoints they are measured between:
// up = mid(up_from) -> up_to, lateral = lateral_from -> lateral_to.
struct FrameVectors {
  int up_from_a, up_from_b, up_to, lateral_from, lateral_to;
};

FrameVectors frame_vectors(Role role, const JointRoles& roles) {
  if (role == Role::kHips) {
    // Up: pelvis centre (midpoint of the thigh joints) -> spine. Lateral: right -> left thigh.
    return {roles[Role::kLeftHip], roles[Role::kRightHip], roles[Role::kSpine],
            roles[Role::kRightHip], roles[Role::kLeftHip]};
  }
  // Chest. Up: chest -> neck. Lateral: right -> left upper arm.
  return {roles[Role::kChest], roles[Role::kChest], roles[Role::kNeck], roles[Role::kRightShoulder],
          roles[Role::kLeftShoulder]};
}

// Evaluates a frame joint's two vectors relative to `origin`, with `point(j)` giving a joint's
// position in the frame the vectors are wanted in.
template <typename PointFn>
bool frame_at(const FrameVectors& v, PointFn point, Quat& frame) {
  const Vec3 up = point(v.up_to) - 0.5 * (point(v.up_from_a) + point(v.up_from_b));
  return frame_from(up, point(v.lateral_to) - point(v.lateral_from), frame);
}

using TrunkPoint = Retargeter::TrunkPoint;

// Where a trunk point is: the weighted sum of its joints' positions, `point(j)` giving each.
template <typename PointFn>
Vec3 point_at(const TrunkPoint& trunk_point, PointFn point) {
  Vec3 sum = Vec3::Zero();
  for (std::size_t k = 0; k < trunk_point.joints.size(); ++k) {
    if (trunk_point.joints[k] >= 0) sum += trunk_point.weights[k] * point(trunk_point.joints[k]);
  }
  return sum;
}

// The source's frame of a two-vector joint (frame_at), its up measured along the trunk where the
// target's joints sit on it: the hips' up ends at the point the target's spine follows, the
// chest's starts at the point the target's chest follows.
template <typename PointFn>
bool source_frame_at(Role role, const JointRoles& roles, const TrunkPoint& spine_point,
                     const TrunkPoint& chest_point, PointFn point, Quat& frame) {
  const FrameVectors v = frame_vectors(role, roles);
  const Vec3 up =
      role == Role::kHips
          ? Vec3(point_at(spine_point, point) - 0.5 * (point(v.up_from_a) + point(v.up_from_b)))
          : Vec3(point(v.up_to) - point_at(chest_point, point));
  return frame_from(up, point(v.lateral_to) - point(v.lateral_from), frame);
}

bool below(const Skeleton& skeleton, int ancestor, std::initializer_list<int> joints) {
  for (int j : joints) {
    if (j != ancestor && !is_ancestor(skeleton, ancestor, j)) return false;
  }
  return true;
}

struct BonePair {
  Role joint, end;
};
constexpr BonePair kBones[] = {
    {Role::kSpine, Role::kChest},
    {Role::kNeck, Role::kHead},
    {Role::kLeftShoulder, Role::kLeftElbow},
    {Role::kLeftElbow, Role::kLeftWrist},
    {Role::kRightShoulder, Role::kRightElbow},
    {Role::kRightElbow, Role::kRightWrist},
    {Role::kLeftHip, Role::kLeftKnee},
    {Role::kLeftKnee, Role::kLeftAnkle},
    {Role::kLeftAnkle, Role::kLeftToe},
    {Role::kRightHip, Role::kRightKnee},
    {Role::kRightKnee, Role::kRightAnkle},
    {Role::kRightAnkle, Role::kRightToe},
};
// End joints and the role whose bone they follow.
constexpr BonePair kFollowers[] = {
    {Role::kHead, Role::kNeck},
    {Role::kLeftWrist, Role::kLeftElbow},
    {Role::kRightWrist, Role::kRightElbow},
    {Role::kLeftToe, Role::kLeftAnkle},
    {Role::kRightToe, Role::kRightAnkle},
};
// Shorter than this (metres) at rest, a bone gives no direction.
constexpr double kShortBone = 0.01;
// Two rest bone directions within 45 degrees are "the same" (a copied rotation is then faithful).
// Measured between clavicles (in the chest's rest alignment): the salsa rig against the ASF rig
// 23 and 28 degrees, the handshake rig 30 and 31, the Bandai rig (rest pose: every bone along
// one axis) 77 and 103.
const double kSameRestDirectionCos = std::cos(45.0 * 3.14159265358979323846 / 180.0);

constexpr Role kFeet[] = {Role::kLeftAnkle, Role::kLeftToe, Role::kRightAnkle, Role::kRightToe};

std::vector<Vec3> rest_positions(const Skeleton& skeleton, std::vector<Vec3>& offsets,
                                 std::vector<Quat>& identities) {
  const auto n = static_cast<std::size_t>(skeleton.joint_count());
  offsets.resize(n);
  for (std::size_t j = 0; j < n; ++j) offsets[j] = skeleton.joints[j].offset;
  identities.assign(n, Quat::Identity());
  std::vector<Vec3> positions(n);
  std::vector<Quat> world(n);
  forward_kinematics(skeleton, offsets, identities, positions, world);
  return positions;
}

// The trunk as a path along its role joints: pelvis centre -> spine -> chest -> neck (the points'
// joints, the pelvis centre being the midpoint of the thigh joints), and its segments' rest
// lengths.
struct TrunkPath {
  std::array<double, 3> lengths{};
  double total() const { return lengths[0] + lengths[1] + lengths[2]; }
};

TrunkPath trunk_path(const std::vector<Vec3>& rest, const JointRoles& roles) {
  const auto at = [&](Role role) { return rest[static_cast<std::size_t>(roles[role])]; };
  const Vec3 pelvis = 0.5 * (at(Role::kLeftHip) + at(Role::kRightHip));
  return {{(at(Role::kSpine) - pelvis).norm(), (at(Role::kChest) - at(Role::kSpine)).norm(),
           (at(Role::kNeck) - at(Role::kChest)).norm()}};
}

// The point `share` of the way along the source's trunk path, as a weighted sum of its joints.
TrunkPoint trunk_point(const TrunkPath& path, const JointRoles& roles, double share) {
  const int lh = roles[Role::kLeftHip], rh = roles[Role::kRightHip];
  const int spine = roles[Role::kSpine], chest = roles[Role::kChest], neck = roles[Role::kNeck];
  double along = std::clamp(share, 0.0, 1.0) * path.total();
  TrunkPoint point;
  if (along < path.lengths[0] || (path.lengths[1] <= 0.0 && path.lengths[2] <= 0.0)) {
    const double w = path.lengths[0] > 0.0 ? std::min(along / path.lengths[0], 1.0) : 1.0;
    point.joints = {lh, rh, spine};
    point.weights = {0.5 * (1.0 - w), 0.5 * (1.0 - w), w};
    return point;
  }
  along -= path.lengths[0];
  if (along < path.lengths[1] || path.lengths[2] <= 0.0) {
    const double w = path.lengths[1] > 0.0 ? std::min(along / path.lengths[1], 1.0) : 1.0;
    point.joints = {spine, chest, -1};
    point.weights = {1.0 - w, w, 0.0};
    return point;
  }
  along -= path.lengths[1];
  const double w = std::min(along / path.lengths[2], 1.0);
  point.joints = {chest, neck, -1};
  point.weights = {1.0 - w, w, 0.0};
  return point;
}

std::string check_roles(const Skeleton& skeleton, const JointRoles& roles,
                        const std::string& name) {
  if (skeleton.joint_count() == 0) return name + ": the skeleton has no joints";
  for (int r = 0; r < kRoleCount; ++r) {
    const int j = roles.joints[static_cast<std::size_t>(r)];
    if (j < 0 || j >= skeleton.joint_count()) {
      return name + ": role " + std::string(role_name(static_cast<Role>(r))) +
             " names no joint of the skeleton (joint index " + std::to_string(j) + ")";
    }
  }
  return {};
}

}  // namespace

Result<Retargeter> Retargeter::create(std::shared_ptr<const Skeleton> source,
                                      const JointRoles& source_roles,
                                      std::shared_ptr<const Skeleton> target,
                                      const JointRoles& target_roles,
                                      const RetargetOptions& options,
                                      const std::string& source_name,
                                      const std::string& target_name) {
  if (!source || !target) return Error{"retarget: no skeleton given"};
  if (std::string e = check_roles(*source, source_roles, source_name); !e.empty()) return Error{e};
  if (std::string e = check_roles(*target, target_roles, target_name); !e.empty()) return Error{e};
  const BodyDimensions source_body = measure_body(*source, source_roles);
  const BodyDimensions target_body = measure_body(*target, target_roles);
  for (const auto& [body, name] :
       {std::pair{&source_body, &source_name}, {&target_body, &target_name}}) {
    if (!(body->leg_length_m > 1e-6) || !std::isfinite(body->leg_length_m)) {
      return Error{*name +
                   ": the legs have no length (the hip, knee and ankle roles sit at one "
                   "place), so strides cannot be scaled"};
    }
  }

  Retargeter r;
  r.source_ = source;
  r.target_ = target;
  r.source_roles_ = source_roles;
  r.target_roles_ = target_roles;
  r.options_ = options;
  r.stride_scale_ =
      options.stride_scale.value_or(target_body.leg_length_m / source_body.leg_length_m);
  if (!(r.stride_scale_ > 0.0) || !std::isfinite(r.stride_scale_)) {
    return Error{"retarget: the stride scale must be a positive number"};
  }

  const Skeleton& s = *source;
  const Skeleton& t = *target;
  std::vector<Vec3> s_offsets, t_offsets;
  std::vector<Quat> s_identity, t_identity;
  const std::vector<Vec3> s_rest = rest_positions(s, s_offsets, s_identity);
  const std::vector<Vec3> t_rest = rest_positions(t, t_offsets, t_identity);
  // The rigs need not put their spine and chest joints at the same heights of the trunk: the
  // target's follow the source's trunk at their own shares of its length.
  // A trunk too short to measure keeps the source's own spine and chest joints.
  r.spine_point_ = TrunkPoint{{source_roles[Role::kSpine], -1, -1}, {1.0, 0.0, 0.0}};
  r.chest_point_ = TrunkPoint{{source_roles[Role::kChest], -1, -1}, {1.0, 0.0, 0.0}};
  if (const TrunkPath s_path = trunk_path(s_rest, source_roles),
      t_path = trunk_path(t_rest, target_roles);
      s_path.total() > kShortBone && t_path.total() > kShortBone) {
    const double spine_share = t_path.lengths[0] / t_path.total();
    const double chest_share = (t_path.lengths[0] + t_path.lengths[1]) / t_path.total();
    r.spine_point_ = trunk_point(s_path, source_roles, spine_share);
    r.chest_point_ = trunk_point(s_path, source_roles, chest_share);
  }
  const auto s_rest_at = [&](int j) { return s_rest[static_cast<std::size_t>(j)]; };
  r.rules_.assign(static_cast<std::size_t>(t.joint_count()), JointRule{});
  auto rule_of = [&](int joint) -> JointRule& { return r.rules_[static_cast<std::size_t>(joint)]; };
  auto free = [&](int joint) {
    return rule_of(joint).rule == Rule::kRest &&
           !t.joints[static_cast<std::size_t>(joint)].end_site;
  };

  auto rest_length = [](const std::vector<Vec3>& rest, int a, int b) {
    return (rest[static_cast<std::size_t>(a)] - rest[static_cast<std::size_t>(b)]).norm();
  };
  // Hips and chest: two vectors each. The alignment takes the target's rest frame to the source's.
  for (const Role role : {Role::kHips, Role::kChest}) {
    const int tj = target_roles[role], sj = source_roles[role];
    if (!free(tj)) continue;
    if (role == Role::kChest && (rest_length(t_rest, tj, target_roles[Role::kNeck]) < kShortBone ||
                                 rest_length(s_rest, sj, source_roles[Role::kNeck]) < kShortBone)) {
      // The neck joint sits on the chest joint (the CMU MotionBuilder rig): no up vector. The
      // chest then turns like the source's, through the rest alignment of the shoulder line, and
      // the smallest swing makes the shoulder line exact.
      const int tl = target_roles[Role::kLeftShoulder], tr = target_roles[Role::kRightShoulder];
      const int sl = source_roles[Role::kLeftShoulder], sr = source_roles[Role::kRightShoulder];
      if (!below(t, tj, {tl, tr}) || !below(s, sj, {sl, sr})) continue;
      const Vec3 t_line =
          t_rest[static_cast<std::size_t>(tl)] - t_rest[static_cast<std::size_t>(tr)];
      const Vec3 s_line =
          s_rest[static_cast<std::size_t>(sl)] - s_rest[static_cast<std::size_t>(sr)];
      if (!(t_line.norm() > 1e-9) || !(s_line.norm() > 1e-9)) continue;
      rule_of(tj) = {Rule::kDirection,
                     sj,
                     tl,
                     sl,
                     -1,
                     -1,
                     Quat::FromTwoVectors(t_line, s_line).normalized(),
                     tr,
                     sr};
      continue;
    }
    const FrameVectors tv = frame_vectors(role, target_roles),
                       sv = frame_vectors(role, source_roles);
    if (!below(t, tj, {tv.up_from_a, tv.up_from_b, tv.up_to, tv.lateral_from, tv.lateral_to}) ||
        !below(s, sj, {sv.up_from_a, sv.up_from_b, sv.up_to, sv.lateral_from, sv.lateral_to})) {
      continue;
    }
    Quat t_frame, s_frame;
    if (!frame_at(
            tv, [&](int j) { return t_rest[static_cast<std::size_t>(j)]; }, t_frame) ||
        !source_frame_at(role, source_roles, r.spine_point_, r.chest_point_, s_rest_at, s_frame)) {
      continue;
    }
    rule_of(tj) = {Rule::kFrame, sj, -1, -1, -1, -1, (s_frame * t_frame.conjugate()).normalized()};
  }
  // Bones: the alignment is the smallest rotation taking the target's rest bone to the source's.
  for (const BonePair& bone : kBones) {
    const int tj = target_roles[bone.joint], te = target_roles[bone.end];
    const int sj = source_roles[bone.joint], se = source_roles[bone.end];
    if (!free(tj) || !is_ancestor(t, tj, te) || !is_ancestor(s, sj, se)) continue;
    // The spine bone runs between the points of the source's trunk the target's spine and chest
    // follow.
    const bool spine = bone.joint == Role::kSpine;
    const Vec3 t_dir = t_rest[static_cast<std::size_t>(te)] - t_rest[static_cast<std::size_t>(tj)];
    const Vec3 s_dir =
        spine ? Vec3(point_at(r.chest_point_, s_rest_at) - point_at(r.spine_point_, s_rest_at))
              : Vec3(s_rest_at(se) - s_rest_at(sj));
    if (!(t_dir.norm() > 1e-9) || !(s_dir.norm() > 1e-9)) continue;
    rule_of(tj) = {Rule::kDirection,
                   sj,
                   te,
                   se,
                   -1,
                   -1,
                   Quat::FromTwoVectors(t_dir, s_dir).normalized(),
                   tj,
                   spine ? kTrunkPoints : sj};
  }
  // End joints follow their parent role's bone.
  for (const BonePair& follower : kFollowers) {
    const int tj = target_roles[follower.joint], tp = target_roles[follower.end];
    const int sj = source_roles[follower.joint], sp = source_roles[follower.end];
    if (!free(tj) || !is_ancestor(t, tp, tj) || !is_ancestor(s, sp, sj)) continue;
    rule_of(tj) = {Rule::kFollow, sj, -1, -1, tp, sp, Quat::Identity()};
  }
  // The head faces as the source's does, when both rigs say where their heads face.
  if (options.source_head_correction && options.target_head_correction) {
    const int th = target_roles[Role::kHead];
    if (free(th) || rule_of(th).rule == Rule::kFollow) {
      rule_of(th) = {Rule::kFacing,
                     source_roles[Role::kHead],
                     -1,
                     -1,
                     -1,
                     -1,
                     (*options.source_head_correction * options.target_head_correction->conjugate())
                         .normalized()};
    }
  }
  // Joints between two roles copy the joint at the same place on the source's path, when the
  // paths have the same length.
  std::vector<int> role_of_target(static_cast<std::size_t>(t.joint_count()), -1);
  for (int role = kRoleCount - 1; role >= 0; --role) {
    role_of_target[static_cast<std::size_t>(target_roles.joints[static_cast<std::size_t>(role)])] =
        role;
  }
  for (int role = 0; role < kRoleCount; ++role) {
    const int tj = target_roles.joints[static_cast<std::size_t>(role)];
    int tp = t.joints[static_cast<std::size_t>(tj)].parent;
    while (tp >= 0 && role_of_target[static_cast<std::size_t>(tp)] < 0) {
      tp = t.joints[static_cast<std::size_t>(tp)].parent;
    }
    if (tp < 0) continue;
    const int parent_role = role_of_target[static_cast<std::size_t>(tp)];
    const int sj = source_roles.joints[static_cast<std::size_t>(role)];
    const int sp = source_roles.joints[static_cast<std::size_t>(parent_role)];
    if (!is_ancestor(s, sp, sj)) continue;
    const std::vector<int> t_between = joints_between(t, tp, tj);
    const std::vector<int> s_between = joints_between(s, sp, sj);
    if (t_between.size() == s_between.size()) {
      for (std::size_t k = 0; k < t_between.size(); ++k) {
        if (free(t_between[k])) {
          rule_of(t_between[k]) = {Rule::kCopy, s_between[k], -1, -1, tp, -1, Quat::Identity()};
        }
      }
    }
    // A clavicle: where the upper arm joint sits decides the shoulder line and every arm feature.
    // A copied rotation is faithful only when both clavicles start from the same rest direction;
    // otherwise (another joint count, or a rest pose that is no human pose: the Bandai rig's
    // copied clavicles tilted its shoulder line by a standard deviation of that feature) the
    // clavicle is turned like a bone, from itself to the upper arm joint, along the source's last
    // joint before its upper arm (its clavicle, or the chest when it has none).
    const bool is_shoulder = role == static_cast<int>(Role::kLeftShoulder) ||
                             role == static_cast<int>(Role::kRightShoulder);
    if (!is_shoulder || t_between.empty()) continue;
    const int clavicle = t_between.back();
    const int source_start = s_between.empty() ? sp : s_between.back();
    const Vec3 t_dir =
        t_rest[static_cast<std::size_t>(tj)] - t_rest[static_cast<std::size_t>(clavicle)];
    const Vec3 s_dir =
        s_rest[static_cast<std::size_t>(sj)] - s_rest[static_cast<std::size_t>(source_start)];
    if (!(t_dir.norm() > kShortBone) || !(s_dir.norm() > kShortBone)) continue;
    if (rule_of(clavicle).rule == Rule::kCopy) {
      const Vec3 t_dir_in_source = rule_of(tp).alignment * t_dir;
      if (t_dir_in_source.normalized().dot(s_dir.normalized()) > kSameRestDirectionCos) continue;
    } else if (rule_of(clavicle).rule != Rule::kRest) {
      continue;
    }
    rule_of(clavicle) = {Rule::kDirection,
                         source_start,
                         tj,
                         sj,
                         -1,
                         -1,
                         Quat::FromTwoVectors(t_dir, s_dir).normalized(),
                         clavicle,
                         source_start};
  }

  const auto sn = static_cast<std::size_t>(s.joint_count());
  const auto tn = static_cast<std::size_t>(t.joint_count());
  r.source_positions_.resize(sn);
  r.source_world_.resize(sn);
  r.target_positions_.resize(tn);
  r.target_world_.resize(tn);
  return r;
}

void Retargeter::retarget_frame(std::span<const Vec3> source_translations_ls,
                                std::span<const Quat> source_rotations_ls,
                                std::span<Vec3> target_translations_ls,
                                std::span<Quat> target_rotations_ls) {
  const Skeleton& s = *source_;
  const Skeleton& t = *target_;
  assert(source_translations_ls.size() == s.joints.size() &&
         source_rotations_ls.size() == s.joints.size());
  assert(target_translations_ls.size() == t.joints.size() &&
         target_rotations_ls.size() == t.joints.size());
  forward_kinematics(s, source_translations_ls, source_rotations_ls, source_positions_,
                     source_world_);
  auto ps = [&](int j) { return source_positions_[static_cast<std::size_t>(j)]; };
  auto ws = [&](int j) { return source_world_[static_cast<std::size_t>(j)]; };

  // Pass 1: rest offsets, and the local rotations that do not depend on other joints (so that
  // the bone vectors of pass 2 see this frame's in-between joints).
  const auto tn = t.joints.size();
  for (std::size_t j = 0; j < tn; ++j) {
    target_translations_ls[j] = t.joints[j].offset;
    const JointRule& rule = rules_[j];
    if (rule.rule == Rule::kCopy) {
      const Quat& q = rules_[static_cast<std::size_t>(rule.parent_role)].alignment;
      target_rotations_ls[j] =
          (q.conjugate() * source_rotations_ls[static_cast<std::size_t>(rule.source)] * q)
              .normalized();
    } else {
      target_rotations_ls[j] = Quat::Identity();
    }
  }
  target_translations_ls[0] = Vec3::Zero();

  // Pass 2, parents first: world rotations of the role joints, then their local rotations.
  for (std::size_t j = 0; j < tn; ++j) {
    const int parent = t.joints[j].parent;
    const Quat parent_world =
        parent < 0 ? Quat::Identity() : target_world_[static_cast<std::size_t>(parent)];
    const JointRule& rule = rules_[j];
    const int joint = static_cast<int>(j);
    Quat world = Quat::Identity();
    switch (rule.rule) {
      case Rule::kRest:
      case Rule::kCopy:
        target_world_[j] = parent_world * target_rotations_ls[j];
        continue;
      case Rule::kDirection: {
        const Vec3 bone_ls =
            chain_vector(t, joint, rule.target_end, target_translations_ls, target_rotations_ls) -
            chain_vector(t, joint, rule.target_start, target_translations_ls, target_rotations_ls);
        world = ws(rule.source) * rule.alignment;
        const Vec3 wanted = rule.source_start == kTrunkPoints
                                ? Vec3(point_at(chest_point_, ps) - point_at(spine_point_, ps))
                                : Vec3(ps(rule.source_end) - ps(rule.source_start));
        const Vec3 current = world * bone_ls;
        if (wanted.norm() > 1e-9 && current.norm() > 1e-9) {
          world = Quat::FromTwoVectors(current, wanted) * world;
        }
        break;
      }
      case Rule::kFrame: {
        const Role role = joint == target_roles_[Role::kHips] ? Role::kHips : Role::kChest;
        Quat local_frame, source_frame;
        const bool ok =
            frame_at(
                frame_vectors(role, target_roles_),
                [&](int e) {
                  return chain_vector(t, joint, e, target_translations_ls, target_rotations_ls);
                },
                local_frame) &&
            source_frame_at(role, source_roles_, spine_point_, chest_point_, ps, source_frame);
        world = ok ? source_frame * local_frame.conjugate() : ws(rule.source) * rule.alignment;
        break;
      }
      case Rule::kFacing:
        world = ws(rule.source) * rule.alignment;
        break;
      case Rule::kFollow: {
        const Quat& q = rules_[static_cast<std::size_t>(rule.parent_role)].alignment;
        world = target_world_[static_cast<std::size_t>(rule.parent_role)] * q.conjugate() *
                ws(rule.source_parent_role).conjugate() * ws(rule.source) * q;
        break;
      }
    }
    world.normalize();
    target_world_[j] = world;
    target_rotations_ls[j] = (parent_world.conjugate() * world).normalized();
  }

  // Root: the target posed at the origin, then moved so that its pelvis centre follows the
  // source's scaled path and its lowest foot point sits at the source's scaled height.
  forward_kinematics(t, target_translations_ls, target_rotations_ls, target_positions_,
                     target_world_);
  const double k = stride_scale_;
  const Vec3 source_pelvis = pelvis_centre(source_positions_, source_roles_);
  const Vec3 target_pelvis = pelvis_centre(target_positions_, target_roles_);
  Vec3 shift = k * source_pelvis - target_pelvis;
  if (options_.feet_on_floor) {
    double source_low = std::numeric_limits<double>::infinity();
    double target_low = std::numeric_limits<double>::infinity();
    for (const Role foot : kFeet) {
      source_low = std::min(source_low, ps(source_roles_[foot]).y());
      target_low = std::min(target_low,
                            target_positions_[static_cast<std::size_t>(target_roles_[foot])].y());
    }
    shift.y() = k * source_low - target_low;
  }
  target_translations_ls[0] = shift;
}

void set_head_corrections(RetargetOptions& options, const Clip& source,
                          const JointRoles& source_roles, const Clip& target_motion,
                          const JointRoles& target_roles) {
  options.source_head_correction.reset();
  options.target_head_correction.reset();
  if (rest_pose_stands(source.skeleton(), source_roles) &&
      rest_pose_stands(target_motion.skeleton(), target_roles)) {
    return;
  }
  Result<Quat> from = head_correction(source, source_roles);
  Result<Quat> to = head_correction(target_motion, target_roles);
  if (!from || !to) return;
  options.source_head_correction = from.value();
  options.target_head_correction = to.value();
}

Result<Clip> retarget_clip(const Clip& source, const JointRoles& source_roles,
                           std::shared_ptr<const Skeleton> target, const JointRoles& target_roles,
                           const RetargetOptions& options, const std::string& source_name,
                           const std::string& target_name) {
  Result<Retargeter> made = Retargeter::create(source.skeleton_ptr(), source_roles, target,
                                               target_roles, options, source_name, target_name);
  if (!made) return made.error();
  Retargeter& retargeter = made.value();
  Clip out(std::move(target), source.frame_rate(), source.frame_count());
  for (int f = 0; f < source.frame_count(); ++f) {
    retargeter.retarget_frame(source.translations_ls(f), source.rotations_ls(f),
                              out.translations_ls(f), out.rotations_ls(f));
  }
  return out;
}

}  // namespace duet
