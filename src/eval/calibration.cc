#include "duet/eval/calibration.h"

#include <algorithm>
#include <cmath>

namespace duet {

void CalibrationAccumulator::add(double confidence, bool correct) {
  const double c = std::isfinite(confidence) ? std::clamp(confidence, 0.0, 1.0) : 0.0;
  // [0, 0.1), ..., [0.9, 1.0]: a confidence of exactly 1 belongs to the last bin.
  const int bin = std::min(static_cast<int>(c * kReliabilityBins), kReliabilityBins - 1);
  Sums& s = bins_[static_cast<std::size_t>(bin)];
  ++s.frames;
  s.correct += correct ? 1 : 0;
  s.confidence += c;
  ++frames_;
}

void CalibrationAccumulator::merge(const CalibrationAccumulator& other) {
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    bins_[b].frames += other.bins_[b].frames;
    bins_[b].correct += other.bins_[b].correct;
    bins_[b].confidence += other.bins_[b].confidence;
  }
  frames_ += other.frames_;
}

ReliabilityDiagram CalibrationAccumulator::diagram() const {
  ReliabilityDiagram out{};
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    const Sums& s = bins_[b];
    out[b].frames = s.frames;
    if (s.frames == 0) continue;
    const auto n = static_cast<double>(s.frames);
    out[b].mean_confidence = s.confidence / n;
    out[b].accuracy = static_cast<double>(s.correct) / n;
  }
  return out;
}

double CalibrationAccumulator::expected_calibration_error() const {
  if (frames_ == 0) return 0.0;
  double ece = 0.0;
  for (const ReliabilityBin& bin : diagram()) {
    ece += static_cast<double>(bin.frames) * std::abs(bin.accuracy - bin.mean_confidence);
  }
  return ece / static_cast<double>(frames_);
}

}  // namespace duet
