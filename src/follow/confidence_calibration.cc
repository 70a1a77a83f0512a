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
    // band 0: 254364 frames
    {0.5805f, 0.5805f, 0.5805f, 0.5805f, 0.5808f, 0.5857f, 0.5906f, 0.5956f, 0.6675f, 0.9483f,
     0.9483f, 0.9939f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 1: 15277 frames
    {0.3333f, 0.3333f, 0.3333f, 0.3333f, 0.3333f, 0.3333f, 0.3333f, 0.3333f, 0.7763f, 0.9823f,
     0.9823f, 0.9862f, 0.9923f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 2: 13608 frames
    {0.0000f, 0.0000f, 0.0000f, 0.0000f, 0.0479f, 0.1113f, 0.1723f, 0.2175f, 0.4820f, 0.8340f,
     0.8340f, 0.9132f, 0.9545f, 0.9646f, 0.9937f, 0.9962f, 0.9979f, 0.9991f, 0.9994f, 0.9997f,
     1.0000f},
    // band 3: 7636 frames
    {0.2500f, 0.2500f, 0.2500f, 0.2648f, 0.2874f, 0.3100f, 0.3798f, 0.4651f, 0.6013f, 0.7140f,
     0.7140f, 0.8336f, 0.8635f, 0.8980f, 0.9381f, 0.9530f, 0.9660f, 0.9766f, 0.9853f, 0.9911f,
     0.9970f},
    // band 4: 8920 frames
    {0.1290f, 0.1290f, 0.1290f, 0.1331f, 0.1378f, 0.2610f, 0.3721f, 0.4609f, 0.5292f, 0.6526f,
     0.6526f, 0.7592f, 0.8958f, 0.9067f, 0.9402f, 0.9458f, 0.9736f, 0.9831f, 0.9865f, 0.9919f,
     0.9972f},
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
