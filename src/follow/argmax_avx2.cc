// AVX2: the argmax of the posterior (eq. 8-9) in two vector passes, the largest value and then
// its first index, so that ties go to the lowest state exactly as in the scalar loop. Compiled for
// any x86-64; called only where the CPU has AVX2.
#if defined(__x86_64__)
#include <immintrin.h>

#include <algorithm>

#include "kernels_avx2.h"

namespace duet::follow_detail::avx2 {

__attribute__((target("avx2,fma"))) int argmax(const float* values, int count) noexcept {
  int i = 0;
  float best = values[0];
  if (count >= 32) {
    __m256 m0 = _mm256_loadu_ps(values);
    __m256 m1 = _mm256_loadu_ps(values + 8);
    __m256 m2 = _mm256_loadu_ps(values + 16);
    __m256 m3 = _mm256_loadu_ps(values + 24);
    for (i = 32; i + 32 <= count; i += 32) {
      m0 = _mm256_max_ps(m0, _mm256_loadu_ps(values + i));
      m1 = _mm256_max_ps(m1, _mm256_loadu_ps(values + i + 8));
      m2 = _mm256_max_ps(m2, _mm256_loadu_ps(values + i + 16));
      m3 = _mm256_max_ps(m3, _mm256_loadu_ps(values + i + 24));
    }
    alignas(32) float lanes[8];
    _mm256_store_ps(lanes, _mm256_max_ps(_mm256_max_ps(m0, m1), _mm256_max_ps(m2, m3)));
    best = *std::max_element(lanes, lanes + 8);
  }
  for (; i < count; ++i) best = std::max(best, values[i]);
  // The first index that holds best.
  const __m256 target = _mm256_set1_ps(best);
  int j = 0;
  for (; j + 8 <= count; j += 8) {
    const int hits =
        _mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(values + j), target, _CMP_EQ_OQ));
    if (hits != 0) return j + __builtin_ctz(static_cast<unsigned>(hits));
  }
  for (; j < count; ++j) {
    if (values[j] == best) return j;
  }
  return 0;  // not reached for finite values
}

}  // namespace duet::follow_detail::avx2

#endif  // __x86_64__
