#include "duet/live/lost_confidence.h"

#include <algorithm>
#include <cmath>
#include <span>

#include "duet/math/lookup_table.h"

namespace duet {
namespace {

constexpr int kInputs = 2;  // InputPoints::kFullBody, kHeadHands

// Fitted by scripts/fit_lost_confidence.py on `duet eval --trackers hmm --no-partner-metrics
// --rigs all --takes 0,1,...,13 --seed S --non-dance none --no-lost-confidence --frames-csv` for
// seeds 23 and 31: the whole body with the cases clean, tempo-slow, tempo-fast, improv,
// improv-pause, noise, 30hz-noisy, improv-30hz-noisy, harsh, suit-drift, tilted, dropouts,
// body-size, late-frames; three points (`--input-points head,hands`) with clean, tempo-fast,
// noise, improv, improv-library, improv-30hz-noisy, harsh, suit-drift. The reported evaluation
// uses seeds 1 and 7.
constexpr float kTable[kInputs][kConfidenceKnotCount] = {
    // whole body: fitted on full_23.csv, full_31.csv
    // 4893 lost frames, 0.836 claimed, 0.787 right
    {0.2500f, 0.2567f, 0.2844f, 0.3121f, 0.3293f, 0.3328f, 0.6386f, 0.6396f, 0.6431f, 0.7310f,
     0.7750f, 0.9318f, 1.0000f},
    // head and hands: fitted on points_23.csv, points_31.csv
    // 80755 lost frames, 0.500 claimed, 0.274 right
    {0.0576f, 0.1031f, 0.1571f, 0.2127f, 0.2420f, 0.2480f, 0.2863f, 0.3033f, 0.3420f, 0.3531f,
     0.4819f, 0.6829f, 0.9623f},
};

}  // namespace

float LostConfidence::apply(float confidence, InputPoints points) noexcept {
  const float c = std::isfinite(confidence) ? std::clamp(confidence, 0.0f, 1.0f) : 0.0f;
  const float* row = kTable[points == InputPoints::kHeadHands ? 1 : 0];
  return interpolate_knots(kConfidenceKnots, std::span<const float>(row, kConfidenceKnotCount), c);
}

}  // namespace duet
