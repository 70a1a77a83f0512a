#include "duet/motion/generic_rigs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "duet/math/rotation.h"
#include "duet/motion/role_detection.h"

namespace duet {

namespace {

constexpr std::array<GenericRigInfo, 3> kRigs = {{
    {GenericRig::kGameAvatar, "game-avatar"},
    {GenericRig::kDepthCamera, "depth-camera"},
    {GenericRig::kInertialSuit, "inertial-suit"},
}};

// A rig written as joints at rest positions (metres), each after its parent.
class RigBuilder {
 public:
  void add(const std::string& name, const std::string& parent, const Vec3& position) {
    const int p = parent.empty() ? -1 : skeleton_.find(parent);
    const Vec3 offset = p < 0 ? position : Vec3(position - positions_[static_cast<std::size_t>(p)]);
    std::vector<Channel> channels = {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
    if (p < 0) {
      channels.insert(channels.begin(),
                      {Channel::kXposition, Channel::kYposition, Channel::kZposition});
    }
    skeleton_.joints.push_back(Joint{name, p, offset, std::move(channels), false});
    positions_.push_back(position);
  }
  // Joints each below the one before, the first below `parent`.
  void chain(std::string parent, std::initializer_list<std::pair<std::string, Vec3>> joints) {
    for (const auto& [name, position] : joints) {
      add(name, parent, position);
      parent = name;
    }
  }

  // Every joint without children ends in an End Site `tip` past it (forward for the toes, on
  // along the bone for the rest).
  Skeleton finish() && {
    const std::size_t joints = skeleton_.joints.size();
    std::vector<bool> has_child(joints, false);
    for (const Joint& joint : skeleton_.joints) {
      if (joint.parent >= 0) has_child[static_cast<std::size_t>(joint.parent)] = true;
    }
    for (std::size_t j = 0; j < joints; ++j) {
      if (has_child[j]) continue;
      const Joint& leaf = skeleton_.joints[j];
      Vec3 along = leaf.offset.norm() > 1e-9 ? Vec3(leaf.offset.normalized()) : Vec3::UnitY();
      if (positions_[j].y() < 0.1) along = Vec3::UnitZ();  // a toe: the End Site points forward
      skeleton_.joints.push_back(
          Joint{leaf.name + "_End", static_cast<int>(j), 0.05 * along, {}, true});
    }
    return std::move(skeleton_);
  }

 private:
  Skeleton skeleton_;
  std::vector<Vec3> positions_;
};

Vec3 lerp(const Vec3& a, const Vec3& b, double t) { return a + (b - a) * t; }

// Where a body's landmarks sit, for a body `height` metres tall (a 1.75 m body's, scaled).
struct Body {
  double k;
  Vec3 at(double x, double y, double z) const { return k * Vec3(x, y, z); }
  Vec3 pelvis() const { return at(0.0, 0.98, 0.0); }
  Vec3 chest() const { return at(0.0, 1.30, -0.01); }
  Vec3 neck() const { return at(0.0, 1.50, -0.02); }
  Vec3 head() const { return at(0.0, 1.60, 0.0); }
  // side: +1 left, -1 right.
  Vec3 shoulder(double side) const { return at(0.19 * side, 1.43, -0.02); }
  Vec3 hip(double side) const { return at(0.095 * side, 0.93, 0.0); }
  Vec3 knee(double side) const { return at(0.10 * side, 0.50, 0.01); }
  Vec3 ankle(double side) const { return at(0.105 * side, 0.08, -0.03); }
  Vec3 toe(double side) const { return at(0.11 * side, 0.02, 0.12); }
  // The arm from the shoulder outwards, lowered `down_deg` from horizontal: elbow, wrist, hand.
  std::array<Vec3, 3> arm(double side, double down_deg) const {
    const double a = deg_to_rad(down_deg);
    const Vec3 along(side * std::cos(a), -std::sin(a), 0.0);
    const Vec3 elbow = shoulder(side) + k * 0.29 * along;
    const Vec3 wrist = elbow + k * 0.26 * along;
    return {elbow, wrist, wrist + k * 0.09 * along};
  }
};

Body body_of_height(double height_m) { return Body{height_m / 1.75}; }

Skeleton game_avatar() {
  const Body b = body_of_height(1.80);
  const auto spine = [&](double share) { return lerp(b.pelvis(), b.chest(), share); };
  RigBuilder r;
  r.chain("", {{"root", Vec3::Zero()},
               {"pelvis", b.pelvis()},
               {"spine_01", spine(0.2)},
               {"spine_02", spine(0.45)},
               {"spine_03", spine(0.7)},
               {"spine_04", spine(0.85)},
               {"spine_05", b.chest()},
               {"neck_01", b.neck()},
               {"neck_02", lerp(b.neck(), b.head(), 0.5)},
               {"head", b.head()}});
  for (const auto& [s, side] : {std::pair{"l", 1.0}, std::pair{"r", -1.0}}) {
    const std::string x = std::string("_") + s;
    const auto [elbow, wrist, hand] = b.arm(side, 45.0);
    r.chain("spine_05", {{"clavicle" + x, b.at(0.03 * side, 1.40, 0.0)},
                         {"upperarm" + x, b.shoulder(side)},
                         {"lowerarm" + x, elbow},
                         {"hand" + x, wrist},
                         {"middle_01" + x, hand}});
    r.chain("pelvis", {{"thigh" + x, b.hip(side)},
                       {"calf" + x, b.knee(side)},
                       {"foot" + x, b.ankle(side)},
                       {"ball" + x, b.toe(side)}});
    // Twist helpers beside the limb joints, halfway along their bones.
    r.add("upperarm_twist_01" + x, "upperarm" + x, lerp(b.shoulder(side), elbow, 0.5));
    r.add("lowerarm_twist_01" + x, "lowerarm" + x, lerp(elbow, wrist, 0.5));
    r.add("thigh_twist_01" + x, "thigh" + x, lerp(b.hip(side), b.knee(side), 0.5));
  }
  return std::move(r).finish();
}

Skeleton depth_camera() {
  const Body b = body_of_height(1.60);
  RigBuilder r;
  r.chain("", {{"SpineBase", b.pelvis()},
               {"SpineMid", lerp(b.pelvis(), b.chest(), 0.5)},
               {"SpineShoulder", b.at(0.0, 1.43, -0.02)},
               {"Neck", b.neck()},
               {"Head", b.head()}});
  for (const auto& [x, side] : {std::pair{"Left", 1.0}, std::pair{"Right", -1.0}}) {
    const auto [elbow, wrist, hand] = b.arm(side, 0.0);
    r.chain("SpineShoulder", {{"Shoulder" + std::string(x), b.shoulder(side)},
                              {"Elbow" + std::string(x), elbow},
                              {"Wrist" + std::string(x), wrist},
                              {"Hand" + std::string(x), hand}});
    r.chain("SpineBase", {{"Hip" + std::string(x), b.hip(side)},
                          {"Knee" + std::string(x), b.knee(side)},
                          {"Ankle" + std::string(x), b.ankle(side)},
                          {"Foot" + std::string(x), b.toe(side)}});
  }
  return std::move(r).finish();
}

Skeleton inertial_suit() {
  const Body b = body_of_height(1.92);
  const auto spine = [&](double share) { return lerp(b.pelvis(), b.chest(), share); };
  RigBuilder r;
  r.chain("", {{"Pelvis", b.pelvis()},
               {"L5", spine(0.25)},
               {"L3", spine(0.5)},
               {"T12", spine(0.75)},
               {"T8", spine(1.0)},
               {"Neck", b.neck()},
               {"Head", b.head()}});
  for (const auto& [s, side] : {std::pair{"Left", 1.0}, std::pair{"Right", -1.0}}) {
    const std::string x = s;
    const auto [elbow, wrist, hand] = b.arm(side, 10.0);
    r.chain("T8", {{x + "Shoulder", b.at(0.04 * side, 1.42, -0.02)},
                   {x + "UpperArm", b.shoulder(side)},
                   {x + "ForeArm", elbow},
                   {x + "Hand", wrist}});
    r.chain("Pelvis", {{x + "UpperLeg", b.hip(side)},
                       {x + "LowerLeg", b.knee(side)},
                       {x + "Foot", b.ankle(side)},
                       {x + "Toe", b.toe(side)}});
  }
  return std::move(r).finish();
}

}  // namespace

std::span<const GenericRigInfo> generic_rigs() { return kRigs; }

const GenericRigInfo* find_generic_rig(std::string_view name) {
  const auto found =
      std::ranges::find_if(kRigs, [&](const GenericRigInfo& rig) { return rig.name == name; });
  return found == kRigs.end() ? nullptr : &*found;
}

Result<GenericRigWithRoles> make_generic_rig_with_roles(GenericRig rig) {
  GenericRigWithRoles made{make_generic_rig(rig), {}};
  RoleDetection detection = detect_roles_report(made.skeleton);
  // Every rig here is made to be read by role detection: a role it misses is a bug.
  if (!detection.complete()) return Error{"rig made in code: " + detection.problem};
  made.roles = std::move(detection.roles);
  return made;
}

Skeleton make_generic_rig(GenericRig rig) {
  switch (rig) {
    case GenericRig::kGameAvatar:
      return game_avatar();
    case GenericRig::kDepthCamera:
      return depth_camera();
    case GenericRig::kInertialSuit:
      return inertial_suit();
  }
  return {};
}

}  // namespace duet
