// AVX2+FMA versions of the per-frame kernels of forward_common.h. Defined only on x86-64, and
// only to be called where cpu_supports(SimdLevel::kAvx2) (forward_common.cc dispatches).
#pragma once

namespace duet::follow_detail::avx2 {

// out[i] = min(||posture_i - posture||^2 + min(||velocity_i - velocity||^2, velocity_cap),
// FLT_MAX) for the num_states states of blocked (TemplateModel::blocked_features(), dims
// dimensions, the last velocity_dims of them velocities). Returns the minimum.
float emission_distances(const float* blocked, int num_states, int dims, int velocity_dims,
                         float velocity_cap, const float* phi, float* out) noexcept;

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
