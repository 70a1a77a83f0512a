// AVX2+FMA: the emission factor of eq. 7 times the prediction (eq. 11), and a plain exp for
// tests. Compiled for any x86-64; called only where the CPU has AVX2 and FMA.
#if defined(__x86_64__)
#include <immintrin.h>

#include "exp_avx2.h"
#include "forward_common.h"
#include "kernels_avx2.h"

namespace duet::follow_detail::avx2 {
namespace {

__attribute__((target("avx2,fma"))) inline __m256i tail_mask(int count) noexcept {
  // Lanes [0, count) set, count in [0, 8).
  return _mm256_cmpgt_epi32(_mm256_set1_epi32(count), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
}

__attribute__((target("avx2,fma"))) inline float horizontal_sum(__m256 v) noexcept {
  __m128 s = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  s = _mm_add_ps(s, _mm_movehl_ps(s, s));
  s = _mm_add_ss(s, _mm_movehdup_ps(s));
  return _mm_cvtss_f32(s);
}

// predicted * exp(max(-d2 / (2 sigma^2), kMinLogEmission) - shift), eight states.
__attribute__((target("avx2,fma"))) inline __m256 weigh(__m256 predicted, __m256 d2, __m256 neg_inv,
                                                        __m256 shift) noexcept {
  const __m256 log_b = _mm256_max_ps(_mm256_mul_ps(d2, neg_inv), _mm256_set1_ps(kMinLogEmission));
  return _mm256_mul_ps(predicted, exp8(_mm256_sub_ps(log_b, shift)));
}

}  // namespace

__attribute__((target("avx2,fma"))) float weigh_emissions(const float* predicted,
                                                          const float* distance_sq,
                                                          float inv_two_sigma_sq, float shift,
                                                          int num_states, float* out) noexcept {
  const __m256 neg_inv = _mm256_set1_ps(-inv_two_sigma_sq);
  const __m256 shift8 = _mm256_set1_ps(shift);
  __m256 sum0 = _mm256_setzero_ps();
  __m256 sum1 = _mm256_setzero_ps();
  int i = 0;
  for (; i + 16 <= num_states; i += 16) {
    const __m256 a =
        weigh(_mm256_loadu_ps(predicted + i), _mm256_loadu_ps(distance_sq + i), neg_inv, shift8);
    const __m256 b = weigh(_mm256_loadu_ps(predicted + i + 8), _mm256_loadu_ps(distance_sq + i + 8),
                           neg_inv, shift8);
    _mm256_storeu_ps(out + i, a);
    _mm256_storeu_ps(out + i + 8, b);
    sum0 = _mm256_add_ps(sum0, a);
    sum1 = _mm256_add_ps(sum1, b);
  }
  for (; i + 8 <= num_states; i += 8) {
    const __m256 a =
        weigh(_mm256_loadu_ps(predicted + i), _mm256_loadu_ps(distance_sq + i), neg_inv, shift8);
    _mm256_storeu_ps(out + i, a);
    sum0 = _mm256_add_ps(sum0, a);
  }
  if (i < num_states) {
    // Lanes past the end load as 0 (0 * a finite exp, exp8 being clamped); the and with the mask
    // zeroes them anyway, so nothing past the end can reach the sum.
    const __m256i mask = tail_mask(num_states - i);
    const __m256 a =
        _mm256_and_ps(weigh(_mm256_maskload_ps(predicted + i, mask),
                            _mm256_maskload_ps(distance_sq + i, mask), neg_inv, shift8),
                      _mm256_castsi256_ps(mask));
    _mm256_maskstore_ps(out + i, mask, a);
    sum0 = _mm256_add_ps(sum0, a);
  }
  return horizontal_sum(_mm256_add_ps(sum0, sum1));
}

__attribute__((target("avx2,fma"))) void exp(const float* x, int count, float* out) noexcept {
  int i = 0;
  for (; i + 8 <= count; i += 8) _mm256_storeu_ps(out + i, exp8(_mm256_loadu_ps(x + i)));
  if (i < count) {
    const __m256i mask = tail_mask(count - i);
    _mm256_maskstore_ps(out + i, mask, exp8(_mm256_maskload_ps(x + i, mask)));
  }
}

}  // namespace duet::follow_detail::avx2

#endif  // __x86_64__
