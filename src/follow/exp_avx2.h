// exp of 8 floats with AVX2+FMA: Cephes' expf (range reduction by ln 2 split in two constants,
// a degree-5 polynomial on [-ln2/2, ln2/2], the power of two built in the exponent bits).
// Include only from files whose callers are target("avx2,fma").
#pragma once

#if defined(__x86_64__)
#include <immintrin.h>

namespace duet::follow_detail::avx2 {

__attribute__((target("avx2,fma"))) inline __m256 exp8(__m256 x) noexcept {
  // Below ln(FLT_MIN) the result would be denormal: return 0, as the flushed scalar path does.
  const __m256 underflow = _mm256_cmp_ps(x, _mm256_set1_ps(-87.33654475f), _CMP_LT_OQ);
  x = _mm256_min_ps(x, _mm256_set1_ps(88.0f));  // keeps 2^n finite
  x = _mm256_max_ps(x, _mm256_set1_ps(-87.33654475f));
  // n = round(x / ln 2); r = x - n ln 2, with ln 2 = C1 + C2 so that n * C1 is exact.
  const __m256 n = _mm256_round_ps(_mm256_mul_ps(x, _mm256_set1_ps(1.44269504088896341f)),
                                   _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  __m256 r = _mm256_fnmadd_ps(n, _mm256_set1_ps(0.693359375f), x);
  r = _mm256_fnmadd_ps(n, _mm256_set1_ps(-2.12194440e-4f), r);
  // exp(r) = 1 + r + r^2 P(r).
  __m256 p = _mm256_set1_ps(1.9875691500e-4f);
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.3981999507e-3f));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(8.3334519073e-3f));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(4.1665795894e-2f));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(1.6666665459e-1f));
  p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(5.0000001201e-1f));
  const __m256 r2 = _mm256_mul_ps(r, r);
  __m256 y = _mm256_fmadd_ps(p, r2, _mm256_add_ps(r, _mm256_set1_ps(1.0f)));
  // 2^n: n + 127 in the exponent field (n in [-126, 127] after the clamps).
  const __m256i exponent =
      _mm256_slli_epi32(_mm256_add_epi32(_mm256_cvtps_epi32(n), _mm256_set1_epi32(127)), 23);
  y = _mm256_mul_ps(y, _mm256_castsi256_ps(exponent));
  return _mm256_andnot_ps(underflow, y);
}

}  // namespace duet::follow_detail::avx2

#endif  // __x86_64__
