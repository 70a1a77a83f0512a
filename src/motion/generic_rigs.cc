#include "duet/motion/generic_rigs.h"

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "duet/math/rotation.h"

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
  RigBuilder r;
  r.add("root", "", Vec3::Zero());
  r.add("pelvis", "root", b.pelvis());
  std::string below = "pelvis";
  const double spine_at[] = {0.2, 0.45, 0.7, 0.85, 1.0};
  for (int i = 0; i < 5; ++i) {
    const std::string name = "spine_0" + std::to_string(i + 1);
    r.add(name, below, lerp(b.pelvis(), b.chest(), spine_at[i]));
    below = name;
  }
  r.add("neck_01", "spine_05", b.neck());
  r.add("neck_02", "neck_01", lerp(b.neck(), b.head(), 0.5));
  r.add("head", "neck_02", b.head());
  for (const auto& [s, side] : {std::pair{"l", 1.0}, std::pair{"r", -1.0}}) {
    const std::string x = std::string("_") + s;
    const auto [elbow, wrist, hand] = b.arm(side, 45.0);
    r.add("clavicle" + x, "spine_05", b.at(0.03 * side, 1.40, 0.0));
    r.add("upperarm" + x, "clavicle" + x, b.shoulder(side));
    r.add("upperarm_twist_01" + x, "upperarm" + x, lerp(b.shoulder(side), elbow, 0.5));
    r.add("lowerarm" + x, "upperarm" + x, elbow);
    r.add("lowerarm_twist_01" + x, "lowerarm" + x, lerp(elbow, wrist, 0.5));
    r.add("hand" + x, "lowerarm" + x, wrist);
    r.add("middle_01" + x, "hand" + x, hand);
    r.add("thigh" + x, "pelvis", b.hip(side));
    r.add("thigh_twist_01" + x, "thigh" + x, lerp(b.hip(side), b.knee(side), 0.5));
    r.add("calf" + x, "thigh" + x, b.knee(side));
    r.add("foot" + x, "calf" + x, b.ankle(side));
    r.add("ball" + x, "foot" + x, b.toe(side));
  }
  return std::move(r).finish();
}

Skeleton depth_camera() {
  const Body b = body_of_height(1.60);
  RigBuilder r;
  r.add("SpineBase", "", b.pelvis());
  r.add("SpineMid", "SpineBase", lerp(b.pelvis(), b.chest(), 0.5));
  r.add("SpineShoulder", "SpineMid", b.at(0.0, 1.43, -0.02));
  r.add("Neck", "SpineShoulder", b.neck());
  r.add("Head", "Neck", b.head());
  for (const auto& [s, side] : {std::pair{"Left", 1.0}, std::pair{"Right", -1.0}}) {
    const std::string x = s;
    const auto [elbow, wrist, hand] = b.arm(side, 0.0);
    r.add("Shoulder" + x, "SpineShoulder", b.shoulder(side));
    r.add("Elbow" + x, "Shoulder" + x, elbow);
    r.add("Wrist" + x, "Elbow" + x, wrist);
    r.add("Hand" + x, "Wrist" + x, hand);
    r.add("Hip" + x, "SpineBase", b.hip(side));
    r.add("Knee" + x, "Hip" + x, b.knee(side));
    r.add("Ankle" + x, "Knee" + x, b.ankle(side));
    r.add("Foot" + x, "Ankle" + x, b.toe(side));
  }
  return std::move(r).finish();
}

Skeleton inertial_suit() {
  const Body b = body_of_height(1.92);
  RigBuilder r;
  r.add("Pelvis", "", b.pelvis());
  std::string below = "Pelvis";
  const char* spine[] = {"L5", "L3", "T12", "T8"};
  for (int i = 0; i < 4; ++i) {
    r.add(spine[i], below, lerp(b.pelvis(), b.chest(), 0.25 * (i + 1)));
    below = spine[i];
  }
  r.add("Neck", "T8", b.neck());
  r.add("Head", "Neck", b.head());
  for (const auto& [s, side] : {std::pair{"Left", 1.0}, std::pair{"Right", -1.0}}) {
    const std::string x = s;
    const auto [elbow, wrist, hand] = b.arm(side, 10.0);
    r.add(x + "Shoulder", "T8", b.at(0.04 * side, 1.42, -0.02));
    r.add(x + "UpperArm", x + "Shoulder", b.shoulder(side));
    r.add(x + "ForeArm", x + "UpperArm", elbow);
    r.add(x + "Hand", x + "ForeArm", wrist);
    r.add(x + "UpperLeg", "Pelvis", b.hip(side));
    r.add(x + "LowerLeg", x + "UpperLeg", b.knee(side));
    r.add(x + "Foot", x + "LowerLeg", b.ankle(side));
    r.add(x + "Toe", x + "Foot", b.toe(side));
  }
  return std::move(r).finish();
}

}  // namespace

std::span<const GenericRigInfo> generic_rigs() { return kRigs; }

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
