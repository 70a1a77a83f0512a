// Where in the library the partner dances, frame by frame (LiveLoop): the follower's estimate,
// except while the follower is lost or between places (in_pause). Then its estimate wanders between
// look-alike places from frame to frame (a headset's three points under noise reported 29 jumps a
// minute), so after a short spell (PlayheadParams::coast_after_lost_s) the partner dances on by
// itself from where it was, at the dancer's last tempo, and goes to the follower's place once the
// dancer is found again. Also decides when the partner jumps (restarts its playhead with a blend).
#pragma once

#include <span>

#include "duet/follow/tracker.h"
#include "duet/partner/partner_synthesis.h"
#include "duet/partner/response_playhead.h"

namespace duet {

struct PartnerPlaceStep {
  int take = 0;
  int frame = 0;        // a frame of that take's response
  // Where between frames the dancer is, from `frame` (FollowResult::frame_offset; 0 while the
  // partner coasts or holds its place).
  double frame_offset = 0.0;
  bool jumped = false;  // the partner restarts there (a blend)
  bool coasting = false;
};

class PartnerPlace {
 public:
  // Back to the first frame: no place yet.
  void reset() noexcept { *this = PartnerPlace{}; }
  // The place for this frame: `result` is the follower's, dt_s the time since the previous
  // frame, `models` the library's takes (non-empty). Allocates nothing.
  PartnerPlaceStep next(const FollowResult& result, double dt_s,
                        std::span<const PartnerModel> models,
                        const PlayheadParams& params) noexcept;

 private:
  int take_ = -1;  // the previous frame's place (-1: none yet)
  int frame_ = 0;
  bool coasting_ = false;     // the follower was lost: the partner danced on by itself
  double coast_frame_ = 0.0;  // where it danced on to (response frame)
  double lost_s_ = 0.0;       // how long the follower has been lost
};

}  // namespace duet
