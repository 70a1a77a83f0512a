// The mirror image of the features: the same dance danced with left and right swapped, as the
// extractor would see it (issue 13's synthetic libraries mirror half their copies). In the body's
// heading frame (x left, y up, z forward) a mirror negates x and swaps every left role with its
// right one; the yaw rate changes sign and the left and right effector speeds swap.
#pragma once

#include <vector>

#include "duet/base/result.h"
#include "duet/features/feature_extractor.h"
#include "duet/features/feature_spec.h"

namespace duet {

// One dimension of the mirrored, standardised feature vector: scale * phi[source] + offset.
struct MirroredDim {
  int source = 0;
  float scale = 1.0f;
  float offset = 0.0f;
};

// The map from standardised features (normalizer applied) to their mirror image, one entry per
// dimension. An error when a posture segment's or point's mirror image is not in the spec.
Result<std::vector<MirroredDim>> feature_mirror(const FeatureSpec& spec,
                                                const FeatureNormalizer& normalizer);

// The role on the other side of the body (a centre role is its own mirror).
Role mirror_role(Role role) noexcept;

}  // namespace duet
