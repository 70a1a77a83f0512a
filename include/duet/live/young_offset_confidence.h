// Confidence while a rig's posture offset is young (issues 10 and 11: calibrated confidence).
//
// The tracker's calibrated confidence (confidence_calibration.h) is fitted on the library's own
// rig. On another rig FollowSession removes a posture offset learnt online (posture_bias.h), and
// until it has been learnt for a few seconds a standing start matches another take's stance as
// well as the dancer's own: on `suit-drift@asf` the first 5 s were within 100 ms on 61 % of frames
// at a mean confidence of 0.92, and that start alone took the case's calibration error to 6.7 %.
// What the tracker cannot see, the session can: how large the offset it removes is and how long
// it has been learnt. The tracker's confidence is mapped through a monotone table per band of the
// two, fitted offline by isotonic regression (scripts/fit_young_offset_confidence.py) on `duet
// eval` performances other than the reported ones, per kind of input (a whole body, or a
// headset's three points, whose offsets are of another size and learnt more slowly). An offset
// learnt for kSettledS or longer leaves the confidence as it is.
#pragma once

#include "duet/features/feature_spec.h"

namespace duet {

class YoungOffsetConfidence {
 public:
  // The confidence seconds after which the table leaves the tracker's confidence as it is.
  static constexpr float kSettledS = 8.0f;

  // confidence: the tracker's, in [0, 1] (non-finite counts as 0); offset_rms and learnt_s:
  // PostureBias::offset_rms() and learnt_s(). Returns a probability in [0, 1], monotone in
  // confidence for a fixed offset and time.
  static float apply(float confidence, float offset_rms, float learnt_s,
                     InputPoints points) noexcept;
};

}  // namespace duet
