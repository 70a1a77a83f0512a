// AVX2+FMA versions of the per-frame kernels of forward_common.h. Defined only on x86-64, and
// only to be called where cpu_supports(SimdLevel::kAvx2) (forward_common.cc dispatches).
#pragma once

#include "forward_common.h"

namespace duet::follow_detail::avx2 {

// follow_detail::emission_distances over the model's blocked features:
// out[i] = min(posture part + min(||velocity_i - velocity||^2, caps.velocity), FLT_MAX), the
// posture part summing every dimension's squared difference, the farthest limb's bounded by
// caps.limb_ratio times the second farthest's (at least caps.limb_floor). Returns the minimum
// of the bounded distances and of the plain ones (no limb bound).
EmissionDistance emission_distances(const TemplateModel& model, DistanceCaps caps, const float* phi,
                                    float* out) noexcept;

// out[i] = predicted[i] * exp(max(-distance_sq[i] * inv_two_sigma_sq, kMinLogEmission) - shift)
// for i < num_states (eq. 7 and the outer factor of eq. 11); returns the sum of out.
float weigh_emissions(const float* predicted, const float* distance_sq, float inv_two_sigma_sq,
                      float shift, int num_states, float* out) noexcept;

// The first index of the largest of values[0..count), count >= 1, values not NaN (as the scalar
// loop in decide).
int argmax(const float* values, int count) noexcept;

// out[i] = exp(x[i]): relative error < 1e-6 where exp(x) is a normal float, 0 below
// ln(FLT_MIN) = -87.34 (denormals are flushed on the per-frame path anyway).
void exp(const float* x, int count, float* out) noexcept;

}  // namespace duet::follow_detail::avx2
