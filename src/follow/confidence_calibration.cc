#include "duet/follow/confidence_calibration.h"

#include <algorithm>
#include <cmath>

#include "duet/math/lookup_table.h"

namespace duet {

namespace {

constexpr int kBands = 5;
constexpr int kKnots = 21;
// Where the table's values sit in coordinate(): scripts/fit_confidence_calibration.py's KNOTS,
// 0, 0.1, ..., 0.9, then 0.9 again and 0.91, ..., 1.0 (its two 0.9 values are the same).
constexpr float kKnotCoordinates[kKnots] = {0.0f,  0.1f,  0.2f,  0.3f,  0.4f,  0.5f,  0.6f,
                                            0.7f,  0.8f,  0.9f,  0.9f,  0.91f, 0.92f, 0.93f,
                                            0.94f, 0.95f, 0.96f, 0.97f, 0.98f, 0.99f, 1.0f};
// Band b holds noise in [kNoiseEdges[b - 1], kNoiseEdges[b]): clean, about 2, 3, 4.5 and 6+
// degrees of rotation noise per joint (RMS).
constexpr float kNoiseEdges[kBands - 1] = {3e-4f, 1.5e-3f, 4e-3f, 8e-3f};

// Fitted by scripts/fit_confidence_calibration.py on `duet eval --trackers hmm --takes 2,4,9,11
// --seed 7 --noise-deg N --frames-csv` for N = 2, 4.5 and 6.93 (every case; the reported
// evaluation uses takes 0, 6, 13 and seed 1).
constexpr float kTable[kBands][kKnots] = {
    // band 0: 254388 frames
    {0.5687f, 0.5687f, 0.5687f, 0.5687f, 0.5687f, 0.5751f, 0.6152f, 0.6553f, 0.6954f, 0.9588f,
     0.9588f, 0.9963f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 1: 15277 frames
    {0.3077f, 0.3077f, 0.3077f, 0.3077f, 0.3077f, 0.3077f, 0.3162f, 0.3287f, 0.7933f, 0.9841f,
     0.9841f, 0.9871f, 0.9921f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 2: 13643 frames
    {0.1667f, 0.1667f, 0.1667f, 0.1667f, 0.1667f, 0.1667f, 0.1667f, 0.2166f, 0.3950f, 0.8764f,
     0.8764f, 0.9150f, 0.9630f, 0.9784f, 0.9959f, 0.9973f, 0.9987f, 0.9994f, 1.0000f, 1.0000f,
     1.0000f},
    // band 3: 13432 frames
    {0.3721f, 0.3721f, 0.3721f, 0.3721f, 0.3721f, 0.3732f, 0.3746f, 0.4170f, 0.4931f, 0.8279f,
     0.8279f, 0.9451f, 0.9817f, 0.9910f, 0.9942f, 0.9969f, 0.9991f, 1.0000f, 1.0000f, 1.0000f,
     1.0000f},
    // band 4: 13511 frames
    {0.3867f, 0.3867f, 0.3867f, 0.3867f, 0.3867f, 0.4024f, 0.4266f, 0.6893f, 0.7230f, 0.8688f,
     0.8688f, 0.9880f, 0.9940f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f, 1.0000f,
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
  const float* row = kTable[band_of(noise, kNoiseEdges)];
  return interpolate_knots(kKnotCoordinates, std::span<const float>(row, kKnots),
                           coordinate(window_mass));
}

}  // namespace duet
