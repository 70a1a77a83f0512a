// The lost flag a forward step reports from the emission's ceiling test (FollowResult::lost),
// shared by the exact, beam and naive steps so that all three report the same way.
#pragma once

#include "duet/follow/follow_params.h"

namespace duet {

class CeilingLostReport {
 public:
  // `gate_lost` is the flag the jump gate and the tempo band went on (past the fixed ceiling or
  // a pause-state majority), `past_ceiling` the emission's own test. A pause-state majority
  // whose best match is within the ceiling (the follower still deciding where the user jumped
  // to) is not lost, unless FollowParams::pause_reported_lost. A missing frame keeps the last
  // frame's ceiling test.
  bool report(const FollowParams& params, bool gate_lost, bool past_ceiling,
              bool missing) noexcept {
    if (params.pause_reported_lost) return gate_lost;
    if (!missing) last_past_ceiling_ = past_ceiling;
    return last_past_ceiling_;
  }

  void reset() noexcept { last_past_ceiling_ = false; }

 private:
  bool last_past_ceiling_ = false;  // the ceiling test of the last frame with features
};

}  // namespace duet
