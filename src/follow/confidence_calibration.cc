#include "duet/follow/confidence_calibration.h"

#include <algorithm>
#include <cmath>

namespace duet {

namespace {

constexpr int kBands = 5;
constexpr int kKnots = 21;  // at coordinates 0, 0.1, ..., 0.9, 0.91, ..., 1.0
// Band b holds noise in [kNoiseEdges[b - 1], kNoiseEdges[b]): clean, about 2, 3, 4.5 and 6+
// degrees of rotation noise per joint (RMS).
constexpr float kNoiseEdges[kBands - 1] = {3e-4f, 1.5e-3f, 4e-3f, 8e-3f};

// Fitted by scripts/fit_confidence_calibration.py on `duet eval --trackers hmm --takes 2,4,9,11
// --seed 7 --noise-deg N --frames-csv` for N = 2, 4.5 and 6.93 (every case; the reported
// evaluation uses takes 0, 6, 13 and seed 1).
constexpr float kTable[kBands][kKnots] = {
    // band 0: 254388 frames
    {0.5973f, 0.5973f, 0.5973f, 0.5973f, 0.5973f, 0.6037f, 0.6101f, 0.6166f, 0.6349f, 0.9474f,
     0.9474f, 0.9938f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 1: 15277 frames
    {0.2857f, 0.2857f, 0.2857f, 0.2857f, 0.2857f, 0.2857f, 0.3472f, 0.4587f, 0.8000f, 0.9752f,
     0.9752f, 0.9842f, 0.9920f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 2: 13627 frames
    {0.0000f, 0.0000f, 0.0231f, 0.0659f, 0.1086f, 0.1514f, 0.1911f, 0.1986f, 0.7922f, 0.9120f,
     0.9120f, 0.9512f, 0.9701f, 0.9850f, 0.9942f, 0.9973f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 3: 13288 frames
    {0.2500f, 0.2500f, 0.2500f, 0.2793f, 0.3392f, 0.3991f, 0.4561f, 0.5226f, 0.6652f, 0.9245f,
     0.9245f, 0.9582f, 0.9846f, 0.9970f, 0.9975f, 0.9978f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 4: 13671 frames
    {0.0000f, 0.0000f, 0.1098f, 0.1425f, 0.2804f, 0.3099f, 0.3409f, 0.5541f, 0.6086f, 0.7750f,
     0.7750f, 0.9730f, 0.9972f, 0.9980f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
};

}  // namespace

float ConfidenceCalibration::coordinate(float window_mass) noexcept {
  const float mass = std::isfinite(window_mass) ? std::clamp(window_mass, 0.0f, 1.0f) : 0.0f;
  if (mass <= 0.9f) return mass;
  const float rest = 1.0f - mass;
  const float nines = rest <= 1e-6f ? 6.0f : std::min(6.0f, -std::log10(rest));
  return 0.9f + 0.1f * (nines - 1.0f) / 5.0f;
}

float ConfidenceCalibration::apply(float window_mass, float noise) noexcept {
  int band = 0;
  while (band < kBands - 1 && noise >= kNoiseEdges[band]) ++band;  // NaN noise: band 0
  const float x = coordinate(window_mass);
  // Knot k sits at k / 10 for k <= 9, at 0.9 + (k - 9) / 100 above.
  const float position = x <= 0.9f ? x * 10.0f : 9.0f + (x - 0.9f) * 100.0f;
  const int k = std::clamp(static_cast<int>(position), 0, kKnots - 2);
  const float t = std::clamp(position - static_cast<float>(k), 0.0f, 1.0f);
  const float* row = kTable[band];
  return std::clamp(row[k] + t * (row[k + 1] - row[k]), 0.0f, 1.0f);
}

}  // namespace duet
