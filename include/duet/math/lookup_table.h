// Reading fitted calibration tables: which band a value falls in, and a piecewise-linear curve
// through knots. ConfidenceCalibration, YoungOffsetConfidence and LostConfidence map a confidence
// through such tables (fitted by scripts/fit_confidence_calibration.py,
// scripts/fit_young_offset_confidence.py and scripts/fit_lost_confidence.py).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

namespace duet {

// The knots of the session's confidence tables (YoungOffsetConfidence, LostConfidence): a
// confidence of 0, 0.1, ..., 0.9, 0.95, 0.99, 1. Must match scripts/fit_young_offset_confidence.py.
inline constexpr float kConfidenceKnots[] = {0.0f, 0.1f, 0.2f, 0.3f,  0.4f,  0.5f, 0.6f,
                                             0.7f, 0.8f, 0.9f, 0.95f, 0.99f, 1.0f};
inline constexpr int kConfidenceKnotCount = 13;
static_assert(sizeof(kConfidenceKnots) / sizeof(float) == kConfidenceKnotCount);

// Band b holds values in [edges[b - 1], edges[b]): 0 below the first edge, edges.size() from the
// last on. NaN falls in band 0. Allocates nothing.
inline int band_of(float value, std::span<const float> edges) noexcept {
  int band = 0;
  const int last = static_cast<int>(edges.size());
  while (band < last && value >= edges[static_cast<std::size_t>(band)]) ++band;
  return band;
}

// The curve through (knots[k], values[k]) at x, linear between knots and held at the end values
// outside them; the result clamped to [0, 1] (the tables are probabilities). knots
// non-decreasing (a repeated knot is a step), as many as values, at least two. NaN reads as the
// first knot. Allocates nothing.
inline float interpolate_knots(std::span<const float> knots, std::span<const float> values,
                               float x) noexcept {
  if (std::isnan(x)) x = knots.front();
  const int count = static_cast<int>(knots.size());
  const int k = std::clamp(
      static_cast<int>(std::upper_bound(knots.begin(), knots.end(), x) - knots.begin()) - 1, 0,
      count - 2);
  const auto at = [](std::span<const float> v, int i) { return v[static_cast<std::size_t>(i)]; };
  const float width = at(knots, k + 1) - at(knots, k);
  const float t = width > 0.0f ? std::clamp((x - at(knots, k)) / width, 0.0f, 1.0f) : 1.0f;
  return std::clamp(at(values, k) + t * (at(values, k + 1) - at(values, k)), 0.0f, 1.0f);
}

}  // namespace duet
