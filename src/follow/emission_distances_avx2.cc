// AVX2+FMA+F16C: the squared distances of the emission (eq. 7) over the blocked template features
// (half precision, TemplateModel::blocked_features), eight states per vector, so no horizontal
// sum is needed. Compiled for any x86-64; called only where the CPU has AVX2, FMA and F16C.
#if defined(__x86_64__)
#include <immintrin.h>

#include <algorithm>
#include <cfloat>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "duet/follow/template_model.h"
#include "kernels_avx2.h"

namespace duet::follow_detail::avx2 {
namespace {

constexpr int kBlock = TemplateModel::kStateBlock;
static_assert(kBlock == 8, "one __m256 per block");
constexpr int kPrefetchBlocks = 8;  // 4 pairs, 6.4 KB at D = 50 (4 and 16: the same)
// Every line of the pair ahead (every second one left 1M states 1.25x slower).
constexpr std::ptrdiff_t kCacheLine = 64;

// The 8 binary16 values at half as floats.
__attribute__((target("avx2,fma,f16c"), always_inline)) inline __m256 load_half(
    const std::uint16_t* half) noexcept {
  return _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(half)));
}

// sum[n] = the sum over d in [begin, end) of (blocks[n][d] - phi[d])^2 for the 8 states of each
// of kBlocks blocks, with kChains accumulators per block: an FMA waits for the one before on its
// accumulator, so independent chains (kBlocks * kChains) keep the FMA units busy, and one
// broadcast of phi[d] serves every block.
template <int kBlocks, int kChains>
__attribute__((target("avx2,fma,f16c"), always_inline)) inline void add_range(
    const std::uint16_t* const* blocks, const float* phi, int begin, int end,
    __m256* sum) noexcept {
  __m256 acc[kBlocks][kChains];
  for (int n = 0; n < kBlocks; ++n)
    for (int c = 0; c < kChains; ++c) acc[n][c] = _mm256_setzero_ps();
  int d = begin;
  for (; d + kChains <= end; d += kChains) {
    for (int c = 0; c < kChains; ++c) {
      const __m256 p = _mm256_set1_ps(phi[d + c]);
      for (int n = 0; n < kBlocks; ++n) {
        const __m256 e = _mm256_sub_ps(load_half(blocks[n] + (d + c) * kBlock), p);
        acc[n][c] = _mm256_fmadd_ps(e, e, acc[n][c]);
      }
    }
  }
  for (int c = 0; d < end; ++d, ++c) {
    const __m256 p = _mm256_set1_ps(phi[d]);
    for (int n = 0; n < kBlocks; ++n) {
      const __m256 e = _mm256_sub_ps(load_half(blocks[n] + d * kBlock), p);
      acc[n][c] = _mm256_fmadd_ps(e, e, acc[n][c]);
    }
  }
  for (int n = 0; n < kBlocks; ++n) {
    __m256 total = acc[n][0];
    for (int c = 1; c < kChains; ++c) total = _mm256_add_ps(total, acc[n][c]);
    sum[n] = total;
  }
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

// The emission distances of eq. 7 for the 8 states of each of kBlocks blocks, saturated at
// FLT_MAX: with the limb bound (bounded) and without it (plain), both with the velocity cap.
template <int kBlocks>
__attribute__((target("avx2,fma,f16c"), always_inline)) inline void block_emission(
    const std::uint16_t* const* blocks, const float* phi, const Layout& layout, __m256* bounded,
    __m256* plain) noexcept {
  constexpr int kChains = 4;    // for the long ranges; a limb's 9 dimensions take 2
  __m256 limb_excess[kBlocks];  // what the limb bound takes off
  for (int n = 0; n < kBlocks; ++n) limb_excess[n] = _mm256_setzero_ps();
  if (layout.limbs_of == nullptr) {
    add_range<kBlocks, kChains>(blocks, phi, 0, layout.posture, plain);
  } else {
    // phi and the block are in the limbs' order (TemplateModel::blocked_dim).
    const std::vector<TemplateModel::DimRange>& limbs = layout.limbs_of->blocked_limbs();
    add_range<kBlocks, 2>(blocks, phi, 0, limbs.front().begin, plain);
    __m256 farthest[kBlocks], second[kBlocks];
    for (int n = 0; n < kBlocks; ++n) farthest[n] = second[n] = _mm256_setzero_ps();
    for (const TemplateModel::DimRange& limb : limbs) {
      __m256 limb_d2[kBlocks];
      add_range<kBlocks, 2>(blocks, phi, limb.begin, limb.end, limb_d2);
      for (int n = 0; n < kBlocks; ++n) {
        plain[n] = _mm256_add_ps(plain[n], limb_d2[n]);
        second[n] = _mm256_max_ps(second[n], _mm256_min_ps(farthest[n], limb_d2[n]));
        farthest[n] = _mm256_max_ps(farthest[n], limb_d2[n]);
      }
    }
    for (int n = 0; n < kBlocks; ++n) {
      const __m256 allowed =
          _mm256_max_ps(_mm256_mul_ps(layout.limb_ratio, second[n]), layout.limb_floor);
      limb_excess[n] = _mm256_sub_ps(farthest[n], _mm256_min_ps(farthest[n], allowed));
    }
  }
  if (layout.posture < layout.dims) {
    __m256 velocity[kBlocks];
    add_range<kBlocks, kChains>(blocks, phi, layout.posture, layout.dims, velocity);
    for (int n = 0; n < kBlocks; ++n) {
      if (layout.velocity_capped) velocity[n] = _mm256_min_ps(velocity[n], layout.velocity_cap);
      plain[n] = _mm256_add_ps(plain[n], velocity[n]);
    }
  }
  // inf (overflow) saturates, as in scalar
  const __m256 max = _mm256_set1_ps(FLT_MAX);
  for (int n = 0; n < kBlocks; ++n) {
    plain[n] = _mm256_min_ps(plain[n], max);
    bounded[n] = _mm256_min_ps(_mm256_sub_ps(plain[n], limb_excess[n]), max);
  }
}

// The emission of blocks [0, 2 * (full_blocks / 2)) two at a time into out, their minima into
// best_bounded / best_plain; returns the first block not done. kPrefetch: the pair kPrefetchBlocks
// ahead is asked for before each pair. From memory (a library beyond the caches) the hardware's
// prefetcher alone left the loop 1.6x slower than one block at a time; within the caches it
// keeps up, and the software prefetch cost 5 %.
template <bool kPrefetch>
__attribute__((target("avx2,fma,f16c"), always_inline)) inline int block_pairs(
    const std::uint16_t* blocked, int full_blocks, const float* phi, const Layout& layout,
    float* out, __m256& best_bounded, __m256& best_plain) noexcept {
  const std::ptrdiff_t block_size = static_cast<std::ptrdiff_t>(layout.dims) * kBlock;
  const std::ptrdiff_t pair_bytes =
      2 * block_size * static_cast<std::ptrdiff_t>(sizeof(std::uint16_t));
  int b = 0;
  for (; b + 2 <= full_blocks; b += 2) {
    const std::uint16_t* blocks[2] = {blocked + b * block_size, blocked + (b + 1) * block_size};
    if constexpr (kPrefetch) {
      const int ahead_block = std::min(b + kPrefetchBlocks, full_blocks - 2);
      const char* ahead = reinterpret_cast<const char*>(blocked + ahead_block * block_size);
      for (std::ptrdiff_t at = 0; at < pair_bytes; at += kCacheLine) {
        _mm_prefetch(ahead + at, _MM_HINT_T0);
      }
    }
    __m256 bounded[2], plain[2];
    block_emission<2>(blocks, phi, layout, bounded, plain);
    for (int n = 0; n < 2; ++n) {
      _mm256_storeu_ps(out + (b + n) * kBlock, bounded[n]);
      best_bounded = _mm256_min_ps(best_bounded, bounded[n]);
      best_plain = _mm256_min_ps(best_plain, plain[n]);
    }
  }
  return b;
}

// Blocked features up to this size are fetched ahead by the hardware alone. Measured at D = 50:
// 2.7 MB (27k states) 5 % faster without the software prefetch, 10 MB (100k) 1.2x and 100 MB
// (1M) 1.45x faster with it.
constexpr std::size_t kHardwarePrefetchBytes = std::size_t{4} << 20;

}  // namespace

__attribute__((target("avx2,fma,f16c"))) EmissionDistance emission_distances(
    const TemplateModel& model, DistanceCaps caps, const float* phi, float* out) noexcept {
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
  phi = model.in_blocked_order(phi, phi_blocked);
  const std::uint16_t* blocked = model.blocked_features().data();
  const int num_states = model.num_states();
  const std::ptrdiff_t block_size = static_cast<std::ptrdiff_t>(layout.dims) * kBlock;
  __m256 best_bounded = _mm256_set1_ps(FLT_MAX);
  __m256 best_plain = best_bounded;
  const int full_blocks = num_states / kBlock;
  // Two blocks at a time: twice the independent FMA chains and half the broadcasts (docs/
  // follower.md, "Half-precision features, two blocks at a time").
  const std::size_t blocked_bytes = model.blocked_features().size_bytes();
  int b =
      blocked_bytes > kHardwarePrefetchBytes
          ? block_pairs<true>(blocked, full_blocks, phi, layout, out, best_bounded, best_plain)
          : block_pairs<false>(blocked, full_blocks, phi, layout, out, best_bounded, best_plain);
  for (; b < full_blocks; ++b) {
    const std::uint16_t* blocks[1] = {blocked + b * block_size};
    __m256 bounded[1], plain[1];
    block_emission<1>(blocks, phi, layout, bounded, plain);
    _mm256_storeu_ps(out + b * kBlock, bounded[0]);
    best_bounded = _mm256_min_ps(best_bounded, bounded[0]);
    best_plain = _mm256_min_ps(best_plain, plain[0]);
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
    const std::uint16_t* blocks[1] = {blocked + full_blocks * block_size};
    __m256 bounded[1], plain[1];
    block_emission<1>(blocks, phi, layout, bounded, plain);
    _mm256_store_ps(lanes, bounded[0]);
    _mm256_store_ps(plain_lanes, plain[0]);
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
