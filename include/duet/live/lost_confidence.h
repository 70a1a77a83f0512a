// Confidence on a lost frame (issue 11: calibrated confidence).
//
// The tracker's confidence is fitted per band of the sensor's noise (confidence_calibration.h) and
// FollowSession's for an offset still young (young_offset_confidence.h), over every frame alike.
// A frame flagged lost says more: no part of the library explains the input there. On three
// points of another rig such frames were right far less often than claimed (at a confidence of
// 0.9 and more, 42-56 % of them within 100 ms; `tempo-fast@handshake`), and they took the
// calibration error of seven cells over 5 %. FollowSession maps a lost frame's confidence through
// a monotone table per kind of input, fitted offline by isotonic regression
// (scripts/fit_lost_confidence.py) on the lost frames of `duet eval` performances other than the
// reported ones. Frames not lost keep their confidence.
#pragma once

#include "duet/features/feature_spec.h"

namespace duet {

class LostConfidence {
 public:
  // confidence: the session's for a frame flagged lost, in [0, 1] (non-finite counts as 0).
  // Returns a probability in [0, 1], monotone in confidence.
  static float apply(float confidence, InputPoints points) noexcept;
};

}  // namespace duet
