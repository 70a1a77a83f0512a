// How well a tracker's confidence is calibrated (issue 11): FollowResult::confidence claims the
// probability that the estimate is within 100 ms of the truth. Frames are grouped into 10 equal
// bins of confidence; a bin's accuracy is the share of its frames that are within 100 ms. The
// expected calibration error (ECE) is sum over bins of (frames in bin / frames) *
// |accuracy - mean confidence| (Guo et al. 2017). Definitions in docs/evaluation.md.
#pragma once

#include <array>

namespace duet {

struct ReliabilityBin {
  long long frames = 0;
  double mean_confidence = 0.0;  // 0 for an empty bin
  double accuracy = 0.0;         // share of the bin's frames within 100 ms; 0 for an empty bin
};

inline constexpr int kReliabilityBins = 10;
using ReliabilityDiagram = std::array<ReliabilityBin, kReliabilityBins>;

class CalibrationAccumulator {
 public:
  // confidence is clamped to [0, 1]; a non-finite one counts as 0 (a claim of nothing).
  void add(double confidence, bool correct);
  void merge(const CalibrationAccumulator& other);

  long long frames() const { return frames_; }
  ReliabilityDiagram diagram() const;
  // Expected calibration error in [0, 1]; 0 without frames.
  double expected_calibration_error() const;

 private:
  struct Sums {
    long long frames = 0;
    long long correct = 0;
    double confidence = 0.0;
  };
  std::array<Sums, kReliabilityBins> bins_{};
  long long frames_ = 0;
};

}  // namespace duet
