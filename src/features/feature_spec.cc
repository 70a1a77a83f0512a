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
