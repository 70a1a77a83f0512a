// AVX2+FMA: the squared distances of the emission (eq. 7) over the blocked template features,
// eight states per vector, so no horizontal sum is needed. Compiled for any x86-64; called only
// where the CPU has AVX2 and FMA.
#if defined(__x86_64__)
#include <immintrin.h>

#include <algorithm>
#include <cfloat>
#include <cstddef>

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

// The capped emission distance of eq. 7 for the 8 states of block, saturated at FLT_MAX.
__attribute__((target("avx2,fma"))) inline __m256 block_emission(const float* block,
                                                                 const float* phi, int posture,
                                                                 int dims, __m256 cap) noexcept {
  __m256 d2 = block_distance(block, phi, 0, posture);
  if (posture < dims) {
    d2 = _mm256_add_ps(d2, _mm256_min_ps(block_distance(block, phi, posture, dims), cap));
  }
  return _mm256_min_ps(d2, _mm256_set1_ps(FLT_MAX));  // inf (overflow) saturates, as in scalar
}

}  // namespace

__attribute__((target("avx2,fma"))) float emission_distances(const float* blocked, int num_states,
                                                             int dims, int velocity_dims,
                                                             float velocity_cap, const float* phi,
                                                             float* out) noexcept {
  const int posture = dims - velocity_dims;
  const __m256 cap = _mm256_set1_ps(velocity_cap);
  const std::ptrdiff_t block_size = static_cast<std::ptrdiff_t>(dims) * kBlock;
  __m256 best = _mm256_set1_ps(FLT_MAX);
  const int full_blocks = num_states / kBlock;
  for (int b = 0; b < full_blocks; ++b) {
    const __m256 d2 = block_emission(blocked + b * block_size, phi, posture, dims, cap);
    _mm256_storeu_ps(out + b * kBlock, d2);
    best = _mm256_min_ps(best, d2);
  }
  alignas(32) float lanes[kBlock];
  _mm256_store_ps(lanes, best);
  float result = *std::min_element(lanes, lanes + kBlock);
  const int rest = num_states - full_blocks * kBlock;
  if (rest > 0) {
    // The padded lanes of the last block are not states: neither stored nor in the minimum.
    _mm256_store_ps(lanes,
                    block_emission(blocked + full_blocks * block_size, phi, posture, dims, cap));
    for (int l = 0; l < rest; ++l) {
      out[full_blocks * kBlock + l] = lanes[l];
      result = std::min(result, lanes[l]);
    }
  }
  return result;
}

}  // namespace duet::follow_detail::avx2

#endif  // __x86_64__
