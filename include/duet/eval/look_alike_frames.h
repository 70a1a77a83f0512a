// Whether a follower's estimate shows the user what the true frame shows (issues 10 and 11).
//
// Every salsa take starts and ends with its two dancers standing, and while the user stands no
// follower can tell one take's standing start from another's: on the library's own rig the
// input is bit for bit its template and the right one wins, on any other rig (or under a suit's
// offset) a look-alike does, and acc@100 scores it as a miss although the user dances the same
// and sees the same partner. This judge says when an estimate is such a look-alike: the frame
// shown is within the time window of the true frame, or some template frame in that window
// looks like it on both sides of the duet:
// - the dancer the user dances, over the whole body (canonical features, docs/features.md);
// - the partner the user sees: its body too, and where it stands and faces relative to the
//   dancer (alignment, method.md 5.1).
// So a look-alike whose partner stands elsewhere, or holds another pose, is still a miss.
#pragma once

#include <vector>

#include "duet/base/result.h"
#include "duet/eval/performance.h"
#include "duet/features/feature_extractor.h"
#include "duet/math/rotation.h"
#include "duet/partner/alignment.h"

namespace duet {

class DuetLibrary;
struct FrameEstimate;

struct LookAlikeOptions {
  // Mean squared standardised distance per dimension of the two bodies' canonical features
  // within which two frames look alike (each side on its own). The follower calls places within
  // 0.004 no jump (FollowParams::jump_alike_distance_per_dim); 0.002 is the dancers standing:
  // over the salsa library it takes every take's standing start and end and few dancing frames.
  float distance_per_dim = 0.002f;
  // How far the partner may stand (horizontally) and face from where it stands and faces at the
  // true frame, relative to the dancer.
  double placement_m = 0.1;
  double facing_rad = deg_to_rad(10.0);
  // The true frame's window: template frames within this of it (the accuracy's 100 ms).
  double window_ms = 100.0;
};

class LookAlikeFrames {
 public:
  // Extracts both dancers' full-body features of every take (allocates; about as long as
  // loading the library's features).
  static Result<LookAlikeFrames> build(const DuetLibrary& library,
                                       const LookAlikeOptions& options = {});

  // Whether `estimate` shows what `truth` shows: the same take within the window, or a
  // look-alike as above. Allocates nothing.
  bool shows_the_same(const TruthFrame& truth, const FrameEstimate& estimate) const noexcept;

 private:
  bool alike(int take_a, int frame_a, int take_b, int frame_b) const noexcept;

  LookAlikeOptions options_;
  double frame_rate_hz_ = 0.0;
  std::vector<int> first_row_;                   // per take: its frame 0's row; one more: the end
  FeatureMatrix template_rows_, response_rows_;  // standardised over the library, per side
  std::vector<SpatialAlignment> placements_;     // per take
};

}  // namespace duet
