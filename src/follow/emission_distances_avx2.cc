// AVX2+FMA: the squared distances of the emission (eq. 7) over the blocked template features,
// eight states per vector, so no horizontal sum is needed. Compiled for any x86-64; called only
// where the CPU has AVX2 and FMA.
#if defined(__x86_64__)
#include <immintrin.h>

#include <algorithm>
#include <cfloat>
#include <cstddef>
#include <vector>

#include "duet/follow/template_model.h"
#include "kernels_avx2.h"

namespace duet::follow_detail::avx2 {
namespace {

constexpr int kBlock = TemplateModel::kStateBlock;
static_assert(kBlock == 8, "one __m256 per block");

// sum over d in [begin, end) of (block[d] - phi[d])^2 for the 8 states of block, with four
// accumulators so that consecutive FMAs do not wait on each other.
__attribute__((target("avx2,fma"))) inline __m256 block_distance(const float* block,
                                                                 const float* phi, int begin,
                                                                 int end) noexcept {
  __m256 acc0 = _mm256_setzero_ps();
  __m256 acc1 = _mm256_setzero_ps();
  __m256 acc2 = _mm256_setzero_ps();
  __m256 acc3 = _mm256_setzero_ps();
  int d = begin;
  for (; d + 4 <= end; d += 4) {
    const __m256 e0 = _mm256_sub_ps(_mm256_loadu_ps(block + d * kBlock), _mm256_set1_ps(phi[d]));
    const __m256 e1 =
        _mm256_sub_ps(_mm256_loadu_ps(block + (d + 1) * kBlock), _mm256_set1_ps(phi[d + 1]));
    const __m256 e2 =
        _mm256_sub_ps(_mm256_loadu_ps(block + (d + 2) * kBlock), _mm256_set1_ps(phi[d + 2]));
    const __m256 e3 =
        _mm256_sub_ps(_mm256_loadu_ps(block + (d + 3) * kBlock), _mm256_set1_ps(phi[d + 3]));
    acc0 = _mm256_fmadd_ps(e0, e0, acc0);
    acc1 = _mm256_fmadd_ps(e1, e1, acc1);
    acc2 = _mm256_fmadd_ps(e2, e2, acc2);
    acc3 = _mm256_fmadd_ps(e3, e3, acc3);
  }
  for (; d < end; ++d) {
    const __m256 e = _mm256_sub_ps(_mm256_loadu_ps(block + d * kBlock), _mm256_set1_ps(phi[d]));
    acc0 = _mm256_fmadd_ps(e, e, acc0);
  }
  return _mm256_add_ps(_mm256_add_ps(acc0, acc1), _mm256_add_ps(acc2, acc3));
}

// The same for a short range (a limb's 9 dimensions): two accumulators, one step of tail.
__attribute__((target("avx2,fma"))) inline __m256 short_distance(const float* block,
                                                                 const float* phi, int begin,
                                                                 int end) noexcept {
  __m256 acc0 = _mm256_setzero_ps();
  __m256 acc1 = _mm256_setzero_ps();
  int d = begin;
  for (; d + 2 <= end; d += 2) {
    const __m256 e0 = _mm256_sub_ps(_mm256_loadu_ps(block + d * kBlock), _mm256_set1_ps(phi[d]));
    const __m256 e1 =
        _mm256_sub_ps(_mm256_loadu_ps(block + (d + 1) * kBlock), _mm256_set1_ps(phi[d + 1]));
    acc0 = _mm256_fmadd_ps(e0, e0, acc0);
    acc1 = _mm256_fmadd_ps(e1, e1, acc1);
  }
  if (d < end) {
    const __m256 e = _mm256_sub_ps(_mm256_loadu_ps(block + d * kBlock), _mm256_set1_ps(phi[d]));
    acc0 = _mm256_fmadd_ps(e, e, acc0);
  }
  return _mm256_add_ps(acc0, acc1);
}

// The same over kSize dimensions from begin, unrolled (the full body's limbs: 9).
template <int kSize>
__attribute__((target("avx2,fma"))) inline __m256 fixed_distance(const float* block,
                                                                 const float* phi,
                                                                 int begin) noexcept {
  __m256 acc0 = _mm256_setzero_ps();
  __m256 acc1 = _mm256_setzero_ps();
  for (int k = 0; k < kSize; ++k) {
    const int d = begin + k;
    const __m256 e = _mm256_sub_ps(_mm256_loadu_ps(block + d * kBlock), _mm256_set1_ps(phi[d]));
    if (k % 2 == 0) {
      acc0 = _mm256_fmadd_ps(e, e, acc0);
    } else {
      acc1 = _mm256_fmadd_ps(e, e, acc1);
    }
  }
  return _mm256_add_ps(acc0, acc1);
}

// A limb's distance: unrolled for the full body's 9 dimensions.
__attribute__((target("avx2,fma"))) inline __m256 limb_distance(
    const float* block, const float* phi, const TemplateModel::DimRange& limb) noexcept {
  if (limb.end - limb.begin == 9) return fixed_distance<9>(block, phi, limb.begin);
  return short_distance(block, phi, limb.begin, limb.end);
}

// What the emission bounds, read once per frame.
struct Layout {
  int posture = 0;
  int dims = 0;
  bool velocity_capped = false;
  __m256 velocity_cap;
  const TemplateModel* limbs_of = nullptr;  // null: the posture in full
  __m256 limb_ratio, limb_floor;
};

// The emission distances of eq. 7 for the 8 states of block, saturated at FLT_MAX: with the
// limb bound (bounded) and without it (plain), both with the velocity cap.
struct BlockDistances {
  __m256 bounded;
  __m256 plain;
};
__attribute__((target("avx2,fma"))) inline BlockDistances block_emission(
    const float* block, const float* phi, const Layout& layout) noexcept {
  __m256 plain;
  __m256 limb_excess = _mm256_setzero_ps();  // what the limb bound takes off
  if (layout.limbs_of == nullptr) {
    plain = block_distance(block, phi, 0, layout.posture);
  } else {
    // phi and the block are in the limbs' order (TemplateModel::blocked_dim).
    const std::vector<TemplateModel::DimRange>& limbs = layout.limbs_of->blocked_limbs();
    plain = short_distance(block, phi, 0, limbs.front().begin);
    __m256 farthest = _mm256_setzero_ps(), second = _mm256_setzero_ps();
    for (const TemplateModel::DimRange& limb : limbs) {
      const __m256 limb_d2 = limb_distance(block, phi, limb);
      plain = _mm256_add_ps(plain, limb_d2);
      second = _mm256_max_ps(second, _mm256_min_ps(farthest, limb_d2));
      farthest = _mm256_max_ps(farthest, limb_d2);
    }
    const __m256 allowed =
        _mm256_max_ps(_mm256_mul_ps(layout.limb_ratio, second), layout.limb_floor);
    limb_excess = _mm256_sub_ps(farthest, _mm256_min_ps(farthest, allowed));
  }
  if (layout.posture < layout.dims) {
    __m256 velocity = block_distance(block, phi, layout.posture, layout.dims);
    if (layout.velocity_capped) velocity = _mm256_min_ps(velocity, layout.velocity_cap);
    plain = _mm256_add_ps(plain, velocity);
  }
  // inf (overflow) saturates, as in scalar
  const __m256 max = _mm256_set1_ps(FLT_MAX);
  plain = _mm256_min_ps(plain, max);
  return {_mm256_min_ps(_mm256_sub_ps(plain, limb_excess), max), plain};
}

}  // namespace

__attribute__((target("avx2,fma"))) EmissionDistance emission_distances(const TemplateModel& model,
                                                                        DistanceCaps caps,
                                                                        const float* phi,
                                                                        float* out) noexcept {
  Layout layout;
  layout.dims = model.num_dims();
  layout.posture = layout.dims - model.velocity_dims();
  layout.velocity_capped = caps.velocity < FLT_MAX;
  layout.velocity_cap = _mm256_set1_ps(caps.velocity);
  if (limbs_bounded(model, caps)) layout.limbs_of = &model;
  layout.limb_ratio = _mm256_set1_ps(caps.limb_ratio);
  layout.limb_floor = _mm256_set1_ps(caps.limb_floor);
  // The input in the blocked features' order (the limbs' order, when the model has limbs).
  alignas(32) float phi_blocked[TemplateModel::kMaxLimbModelDims];
  if (!model.limbs().empty()) {
    for (int d = 0; d < layout.dims; ++d) phi_blocked[model.blocked_dim(d)] = phi[d];
    phi = phi_blocked;
  }
  const float* blocked = model.blocked_features().data();
  const int num_states = model.num_states();
  const std::ptrdiff_t block_size = static_cast<std::ptrdiff_t>(layout.dims) * kBlock;
  __m256 best_bounded = _mm256_set1_ps(FLT_MAX);
  __m256 best_plain = best_bounded;
  const int full_blocks = num_states / kBlock;
  for (int b = 0; b < full_blocks; ++b) {
    const BlockDistances d2 = block_emission(blocked + b * block_size, phi, layout);
    _mm256_storeu_ps(out + b * kBlock, d2.bounded);
    best_bounded = _mm256_min_ps(best_bounded, d2.bounded);
    best_plain = _mm256_min_ps(best_plain, d2.plain);
  }
  alignas(32) float lanes[kBlock];
  alignas(32) float plain_lanes[kBlock];
  _mm256_store_ps(lanes, best_bounded);
  _mm256_store_ps(plain_lanes, best_plain);
  EmissionDistance result{*std::min_element(lanes, lanes + kBlock),
                          *std::min_element(plain_lanes, plain_lanes + kBlock)};
  const int rest = num_states - full_blocks * kBlock;
  if (rest > 0) {
    // The padded lanes of the last block are not states: neither stored nor in the minimum.
    const BlockDistances d2 = block_emission(blocked + full_blocks * block_size, phi, layout);
    _mm256_store_ps(lanes, d2.bounded);
    _mm256_store_ps(plain_lanes, d2.plain);
    for (int l = 0; l < rest; ++l) {
      out[full_blocks * kBlock + l] = lanes[l];
      result.bounded = std::min(result.bounded, lanes[l]);
      result.plain = std::min(result.plain, plain_lanes[l]);
    }
  }
  return result;
}

}  // namespace duet::follow_detail::avx2

#endif  // __x86_64__
