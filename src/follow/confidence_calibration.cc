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
    {0.6188f, 0.6188f, 0.6188f, 0.6188f, 0.6203f, 0.6284f, 0.6365f, 0.6446f, 0.6651f, 0.9824f,
     0.9824f, 0.9986f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 1: 15277 frames
    {0.2857f, 0.2857f, 0.2857f, 0.2857f, 0.2857f, 0.2857f, 0.3588f, 0.4639f, 0.8566f, 0.9833f,
     0.9833f, 0.9898f, 0.9944f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 2: 13634 frames
    {0.0000f, 0.0149f, 0.0515f, 0.0881f, 0.1247f, 0.1593f, 0.1742f, 0.1890f, 0.8242f, 0.9284f,
     0.9284f, 0.9637f, 0.9840f, 0.9895f, 0.9933f, 0.9973f, 0.9986f, 0.9994f, 1.0000f, 1.0000f,
     1.0000f},
    // band 3: 13296 frames
    {0.0000f, 0.0000f, 0.0000f, 0.0770f, 0.1941f, 0.3111f, 0.4053f, 0.5885f, 0.8009f, 0.9156f,
     0.9156f, 0.9625f, 0.9892f, 0.9973f, 0.9975f, 0.9978f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 4: 13656 frames
    {0.0000f, 0.0000f, 0.0945f, 0.1402f, 0.1859f, 0.2456f, 0.3451f, 0.5343f, 0.7719f, 0.9150f,
     0.9150f, 0.9815f, 0.9967f, 0.9982f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
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
