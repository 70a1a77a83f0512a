#include "duet/features/feature_spec.h"

namespace duet {

bool parse_input_points(std::string_view text, InputPoints& points) {
  if (text == "full") {
    points = InputPoints::kFullBody;
    return true;
  }
  if (text == "head,hands" || text == "hands,head") {
    points = InputPoints::kHeadHands;
    return true;
  }
  return false;
}

const char* input_points_name(InputPoints points) {
  return points == InputPoints::kHeadHands ? "head,hands" : "full";
}

namespace {

// 0..3 for the roles of the left arm, right arm, left leg and right leg; -1 for the trunk's.
int limb_of(Role role) {
  switch (role) {
    case Role::kLeftShoulder:
    case Role::kLeftElbow:
    case Role::kLeftWrist:
      return 0;
    case Role::kRightShoulder:
    case Role::kRightElbow:
    case Role::kRightWrist:
      return 1;
    case Role::kLeftHip:
    case Role::kLeftKnee:
    case Role::kLeftAnkle:
    case Role::kLeftToe:
      return 2;
    case Role::kRightHip:
    case Role::kRightKnee:
    case Role::kRightAnkle:
    case Role::kRightToe:
      return 3;
    default:
      return -1;
  }
}

constexpr int kLimbCount = 4;

}  // namespace

std::vector<std::vector<int>> FeatureSpec::limb_dims() const {
  if (input_points == InputPoints::kHeadHands) return {};
  std::vector<std::vector<int>> limbs(kLimbCount);
  // The posture block holds each segment's direction, then each point's position (3 dims each).
  int dim = 0;
  const auto add = [&](int limb) {
    if (limb >= 0) {
      for (int axis = 0; axis < 3; ++axis)
        limbs[static_cast<std::size_t>(limb)].push_back(dim + axis);
    }
    dim += 3;
  };
  for (const BodySegment& segment : posture_segments) {
    const int limb = limb_of(segment.from);
    add(limb == limb_of(segment.to) ? limb : -1);
  }
  for (const Role point : posture_points) add(limb_of(point));
  std::erase_if(limbs, [](const std::vector<int>& dims) { return dims.empty(); });
  return limbs;
}

int FeatureSpec::block_begin(FeatureBlock block) const {
  switch (block) {
    case FeatureBlock::kPosture:
      return 0;
    case FeatureBlock::kRootVelocity:
      return posture_dims();
    case FeatureBlock::kEffectorSpeed:
      return posture_dims() + kRootVelocityDims;
    case FeatureBlock::kCount:
      break;
  }
  return dimension();
}

int FeatureSpec::block_size(FeatureBlock block) const {
  switch (block) {
    case FeatureBlock::kPosture:
      return posture_dims();
    case FeatureBlock::kRootVelocity:
      return kRootVelocityDims;
    case FeatureBlock::kEffectorSpeed:
      return effector_speed_dims();
    case FeatureBlock::kCount:
      break;
  }
  return 0;
}

}  // namespace duet
