#include "duet/features/feature_spec.h"

namespace duet {

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
      return kEffectorSpeedDims;
    case FeatureBlock::kCount:
      break;
  }
  return 0;
}

}  // namespace duet
