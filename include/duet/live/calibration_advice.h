// Whether three points (a headset and two controllers) need a body calibration (issue 10, the
// first hour). Another body holds its hands elsewhere against its head than the library's
// dancers hold theirs; the follower learns that as a posture offset (FollowResult::rig_offset)
// while the user dances, and until it has, places them less surely: three points on the CMU ASF
// and handshake rigs were 7-17 points fewer frames within 100 ms than with the arms-forward
// calibration told, nearly all in the first 5 s. The learnt offset tells those bodies apart:
// its median over frames learnt kSettledOffsetS or longer is 0.006-0.02 on the library's own rig,
// 0.026-0.035 on a proportioned and the Bandai rig (followed as well as the library's), 0.09-0.11
// on the ASF and handshake rigs (docs/evaluation.md, "Three points hold a look-alike").
// `duet follow` prints a note from it, `duet serve` logs it and sends it in `stats`.
#pragma once

#include <array>
#include <optional>

#include "duet/follow/tracker.h"

namespace duet {

class CalibrationAdvice {
 public:
  static constexpr double kSettledOffsetS = 4.0;  // an offset learnt this long counts
  static constexpr float kOtherBodyOffset = 0.06f;
  static constexpr double kMinSettledS = 1.0;  // ... over at least this much input

  // Counts one frame followed for dt_s seconds. Frames without evidence, or whose offset is
  // younger than kSettledOffsetS, do not count. Allocates nothing.
  void observe(const FollowResult& result, double dt_s) noexcept;
  // The median learnt offset (to kResolution) once kMinSettledS of counted input is in and the
  // median is kOtherBodyOffset or more; nullopt otherwise.
  std::optional<float> other_body_offset() const noexcept;
  void reset() noexcept;

  static constexpr float kResolution = 0.001f;

 private:
  static constexpr int kBins = 1000;  // offsets from 0 to 1 (the last bin takes larger ones)
  std::array<int, kBins> counts_{};   // counted frames per offset bin
  int count_ = 0;
  double settled_s_ = 0.0;
};

}  // namespace duet
