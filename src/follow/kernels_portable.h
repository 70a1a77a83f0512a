// Portable versions of the per-frame kernels that read the blocked half-precision features
// (TemplateModel::blocked_features), for CPUs without AVX2: plain loops over the 8 states of a
// block, which the compiler vectorises for whatever the target has (SSE2, NEON).
#pragma once

#include "forward_common.h"

namespace duet::follow_detail::portable {

// follow_detail::emission_distances with caps, as avx2::emission_distances computes it.
EmissionDistance emission_distances(const TemplateModel& model, DistanceCaps caps, const float* phi,
                                    float* out) noexcept;

}  // namespace duet::follow_detail::portable
