// The capped emission distances of eq. 7 in portable C++ over the blocked half-precision features:
// the same blocks, groups and bounds as the AVX2 kernel (emission_distances_avx2.cc), four states
// per vector of GCC and Clang's vector extensions (SSE2, NEON). The per-state pass over each row
// with the limbs' index lists that it replaces took 1.14 ms at 27,495 states, this 0.60
// (BM_EmissionDistances/scalar).
#include <algorithm>
#include <bit>
#include <cfloat>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "duet/follow/template_model.h"
#include "kernels_portable.h"

namespace duet::follow_detail::portable {
namespace {

constexpr int kBlock = TemplateModel::kStateBlock;
// Four states' values: GCC and Clang's vector extensions, one SSE2 or NEON register; a block of 8
// states is two (the 32-byte vector, split by the compiler where the target has no AVX, ran 1.7x
// slower).
using Quad = float __attribute__((vector_size(4 * sizeof(float))));
using HalfQuad = std::uint16_t __attribute__((vector_size(4 * sizeof(std::uint16_t))));
using WordQuad = std::uint32_t __attribute__((vector_size(4 * sizeof(std::uint32_t))));
struct Lanes {
  Quad low = {}, high = {};  // states 0-3 and 4-7 of a block
  float operator[](int l) const { return l < 4 ? low[l] : high[l - 4]; }
};

// Four binary16 values as floats: their exponents and mantissas moved into a float's and scaled
// by 2^112 (the difference of the two exponent biases), exact for every finite half, subnormals
// included (where denormals are flushed, those below 6.1e-5 read as 0). The model holds no
// infinities (TemplateModel::held_precision).
inline Quad half_to_float(const std::uint16_t* halves) noexcept {
  HalfQuad bits;
  std::memcpy(&bits, halves, sizeof(bits));
  const WordQuad words = __builtin_convertvector(bits, WordQuad);
  const WordQuad magnitude = (words & 0x7fffu) << 13;
  const WordQuad sign = (words & 0x8000u) << 16;
  const Quad scaled = std::bit_cast<Quad>(magnitude) * 0x1p112f;
  return std::bit_cast<Quad>(std::bit_cast<WordQuad>(scaled) | sign);
}

// The sum over d in [begin, end) of (block[d] - phi[d])^2 for the 8 states of block.
inline Lanes range_distance(const std::uint16_t* block, const float* phi, int begin,
                            int end) noexcept {
  Lanes acc;
  for (int d = begin; d < end; ++d) {
    const std::uint16_t* values = block + static_cast<std::ptrdiff_t>(d) * kBlock;
    const Quad low = half_to_float(values) - phi[d];
    const Quad high = half_to_float(values + 4) - phi[d];
    acc.low += low * low;
    acc.high += high * high;
  }
  return acc;
}

// Lane by lane.
inline Quad min(Quad a, Quad b) noexcept { return a < b ? a : b; }
inline Quad max(Quad a, Quad b) noexcept { return a > b ? a : b; }
inline Lanes operator+(Lanes a, Lanes b) noexcept { return {a.low + b.low, a.high + b.high}; }
inline Lanes operator-(Lanes a, Lanes b) noexcept { return {a.low - b.low, a.high - b.high}; }
inline Lanes operator*(float a, Lanes b) noexcept { return {a * b.low, a * b.high}; }
inline Lanes min(Lanes a, Lanes b) noexcept { return {min(a.low, b.low), min(a.high, b.high)}; }
inline Lanes max(Lanes a, Lanes b) noexcept { return {max(a.low, b.low), max(a.high, b.high)}; }
inline Lanes splat(float value) noexcept { return {Quad{} + value, Quad{} + value}; }

struct Layout {
  int posture = 0;
  int dims = 0;
  DistanceCaps caps;
  const std::vector<TemplateModel::DimRange>* limbs = nullptr;  // null: the posture in full
};

// The bounded and plain distances of the 8 states of block (as avx2's block_emission).
inline void block_emission(const std::uint16_t* block, const float* phi, const Layout& layout,
                           Lanes& bounded, Lanes& plain) noexcept {
  Lanes limb_excess;
  if (layout.limbs == nullptr) {
    plain = range_distance(block, phi, 0, layout.posture);
  } else {
    plain = range_distance(block, phi, 0, layout.limbs->front().begin);
    Lanes farthest, second;
    for (const TemplateModel::DimRange& limb : *layout.limbs) {
      const Lanes limb_d2 = range_distance(block, phi, limb.begin, limb.end);
      plain = plain + limb_d2;
      second = max(second, min(farthest, limb_d2));
      farthest = max(farthest, limb_d2);
    }
    const Lanes allowed = max(layout.caps.limb_ratio * second, splat(layout.caps.limb_floor));
    limb_excess = farthest - min(farthest, allowed);
  }
  if (layout.posture < layout.dims) {
    const Lanes velocity = range_distance(block, phi, layout.posture, layout.dims);
    plain = plain + min(velocity, splat(layout.caps.velocity));
  }
  const Lanes largest = splat(FLT_MAX);  // inf (overflow) saturates
  plain = min(plain, largest);
  bounded = min(plain - limb_excess, largest);
}

}  // namespace

EmissionDistance emission_distances(const TemplateModel& model, DistanceCaps caps, const float* phi,
                                    float* out) noexcept {
  Layout layout;
  layout.dims = model.num_dims();
  layout.posture = layout.dims - model.velocity_dims();
  layout.caps = caps;
  if (limbs_bounded(model, caps)) layout.limbs = &model.blocked_limbs();
  // The input in the blocked features' order (the limbs' order, when the model has limbs).
  float phi_blocked[TemplateModel::kMaxLimbModelDims];
  phi = model.in_blocked_order(phi, phi_blocked);
  const std::uint16_t* blocked = model.blocked_features().data();
  const std::ptrdiff_t block_size = static_cast<std::ptrdiff_t>(layout.dims) * kBlock;
  const int num_states = model.num_states();
  const int full_blocks = num_states / kBlock;
  Lanes best_bounded = splat(FLT_MAX), best_plain = best_bounded;
  for (int b = 0; b < full_blocks; ++b) {
    Lanes bounded, plain;
    block_emission(blocked + b * block_size, phi, layout, bounded, plain);
    std::memcpy(out + b * kBlock, &bounded.low, sizeof(Quad));
    std::memcpy(out + b * kBlock + 4, &bounded.high, sizeof(Quad));
    best_bounded = min(best_bounded, bounded);
    best_plain = min(best_plain, plain);
  }
  EmissionDistance best;
  for (int l = 0; l < kBlock; ++l) {
    best.bounded = std::min(best.bounded, best_bounded[l]);
    best.plain = std::min(best.plain, best_plain[l]);
  }
  const int rest = num_states - full_blocks * kBlock;
  if (rest > 0) {
    // The padded lanes of the last block are not states: neither stored nor in the minimum.
    Lanes bounded, plain;
    block_emission(blocked + full_blocks * block_size, phi, layout, bounded, plain);
    for (int l = 0; l < rest; ++l) {
      out[full_blocks * kBlock + l] = bounded[l];
      best.bounded = std::min(best.bounded, bounded[l]);
      best.plain = std::min(best.plain, plain[l]);
    }
  }
  return best;
}

}  // namespace duet::follow_detail::portable
