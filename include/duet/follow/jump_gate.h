// Jump decisions that hold (issue 11). The estimate is the posterior's most likely state; under a
// noisy sensor that maximum flickers, one frame to a look-alike place elsewhere in the library and
// back, and every such excursion would be reported as a jump (the partner restarts its playhead
// and blends: 67 false jumps a minute at 3 degrees of noise, nearly all of them the maximum
// stepping back a frame or two). A small move backwards (up to jump_tolerance_frames) is jitter,
// not a jump. A move out of the band's reach is reported only once the new place has held the
// maximum for the hold in template time (a bounded decision delay; until then the best state near
// the old place is reported): FollowParams::jump_hold_s, or under a noisy sensor the hold that
// grows with the estimated noise (noisy_jump_hold_s) or, for a far place the input fits poorly
// taking the maximum from a place followed unexplained_jump_hold_after_s since the last jump,
// unexplained_jump_hold_s, and once the old place's reach holds at most
// jump_old_place_mass of the posterior (a look-alike's brief maximum leaves the old place its
// evidence; a real jump does not).
// Adrift (lost, or the pause state holds the posterior) no place explains the input and the
// maximum wanders between look-alike places from frame to frame (three points under noise: 29
// jumps a minute, nearly all while lost): nothing is reported as a jump during the spell. The
// first frame found again is a jump if it is out of reach of the place reported before the spell,
// over the time the spell lasted. After a lost frame with no such place the new place is taken at
// once. Until the estimate has first settled (FollowParams::jump_settle_s of frames within reach
// with a window mass of at least jump_settle_mass, over which it reached jump_settle_advance_s
// forward of where it began in its take) a far move is the first placement being refined: no jump
// is reported (half the false jumps left at 4 degrees per axis were those, and nearly all of an
// inertial suit's, whose standing start sat on other takes' standing frames).
// A burst of jumps (FollowParams::jump_burst_jumps within jump_burst_s) is a place lost: the jump
// that would complete it is withdrawn and the placement starts again as at the start. A catch-up
// (a move forward within the take, at most jump_catch_up_s past the band's reach) is no jump.
#pragma once

#include <array>
#include <limits>

#include "duet/follow/follow_params.h"
#include "duet/follow/template_model.h"
#include "duet/follow/tracker.h"

namespace duet {

class JumpGate {
 public:
  // Back to the first frame: not settled, no candidate.
  void reset() noexcept {
    forget_candidate();
    settled_s_ = 0.0;
    followed_since_jump_s_ = 0.0;
    forget_advance();
    steady_state_ = -1;
    steps_since_steady_ = 0;
    in_spell_ = false;
    clock_s_ = 0.0;
    recent_jumps_ = 0;
  }

  // `result` holds the posterior's maximum (follow_detail::decide); on return it holds the state
  // to report, with take, frame, confidence and jumped set for it. `posterior` has M entries
  // (mass `total` over M + 1 with the pause state); `previous_state` is the state reported for
  // the previous frame (-1 at the start). The frame is adrift when result.lost (the fixed
  // ceiling) or result.in_pause is set, or `unexplained` (past the noise-scaled lost distance).
  // After a lost frame with no place before it the maximum is taken at once. Allocates nothing.
  void apply(const TemplateModel& model, const FollowParams& params, const float* posterior,
             float total, int previous_state, bool previous_lost, FollowResult& result,
             bool unexplained = false) noexcept;
  // Whether the first placement has settled (FollowParams::jump_settle_s and
  // jump_settle_advance_s).
  bool settled(const FollowParams& params) const noexcept {
    return settled_s_ + 1e-6 >= params.jump_settle_s &&
           advanced_s_ + 1e-6 >= params.jump_settle_advance_s;
  }
  // Whether the estimate has held one place for FollowParams::jump_settle_s, moving or not (the
  // outlier gate's followed place: FollowerHistory::is_outlier).
  bool held_a_place(const FollowParams& params) const noexcept {
    return settled_s_ + 1e-6 >= params.jump_settle_s;
  }
  // The hold (template seconds) at this sensor noise (FollowResult::sensor_noise_per_dim) for a
  // far place whose best distance per dimension is best_distance_per_dim (0: one that fits),
  // leaving a place followed for followed_s (template seconds) since the last reported jump or
  // the first placement (FollowParams::unexplained_jump_hold_after_s).
  static float hold_s(const FollowParams& params, float sensor_noise_per_dim,
                      float best_distance_per_dim = 0.0f,
                      double followed_s = std::numeric_limits<double>::infinity()) noexcept;

 private:
  void forget_candidate() noexcept {
    candidate_state_ = -1;
    held_s_ = 0.0;
  }

  void forget_advance() noexcept {
    advanced_s_ = 0.0;
    advance_origin_ = -1;
    advance_furthest_ = -1;
  }
  // The placement starts (again) at the current place: not settled, no candidate, no time
  // followed since a jump.
  void restart_placement() noexcept {
    settled_s_ = 0.0;
    followed_since_jump_s_ = 0.0;
    forget_advance();
    forget_candidate();
  }
  // A sure frame within reach moved the estimate from `from` to `to`: advanced_s_ is how far
  // forward of where the count began the estimate has been. Jitter back and forth adds nothing
  // (summing each forward step did: a standing start jittering a frame or two about one place
  // settled there).
  void note_advance(const TemplateModel& model, int from, int to) noexcept;
  // While adrift, and on the frame found again: decides the frame and returns true. `over`: the
  // template steps since the frame before the spell (this frame's included).
  bool through_spell(const TemplateModel& model, const FollowParams& params, bool adrift, int over,
                     FollowResult& result) noexcept;
  // Whether the template rows of two states look alike (FollowParams::jump_alike_distance_per_dim):
  // a move between them is no jump.
  static bool looks_alike(const TemplateModel& model, const FollowParams& params, int from,
                          int to) noexcept;
  // Whether a move from `from` to `to` over `steps` template steps is a catch-up
  // (FollowParams::jump_catch_up_s).
  static bool is_catch_up(const TemplateModel& model, const FollowParams& params, int from, int to,
                          int steps) noexcept;
  // A reported jump that would make a burst (FollowParams::jump_burst_jumps within jump_burst_s)
  // is withdrawn and the placement starts again; otherwise its time is kept. Returns whether it
  // still stands.
  bool keeps_jump(const FollowParams& params) noexcept;
  // Any other frame.
  void decide(const TemplateModel& model, const FollowParams& params, const float* posterior,
              float total, int previous_state, bool previous_lost, FollowResult& result) noexcept;

  int steady_state_ = -1;       // the state reported on the last frame not adrift
  int steps_since_steady_ = 0;  // template steps since then
  bool in_spell_ = false;       // adrift since steady_state_ (or since the start)
  double settled_s_ = 0.0;    // how long (template time) the estimate has stayed within reach
  double advanced_s_ = 0.0;   // how far (template time) it has moved forward meanwhile
  int advance_origin_ = -1;   // the state where that count began
  int advance_furthest_ = -1;  // the furthest state in its take reached since
  int candidate_state_ = -1;  // the far place that currently holds the maximum
  double held_s_ = 0.0;       // how long (template time) it has held it
  // How long (template time) the estimate has been followed since the last reported jump or the
  // first placement (spells adrift not counted).
  double followed_since_jump_s_ = 0.0;
  double clock_s_ = 0.0;  // template time since the start (every step, spells included)
  // When the last jumps were reported (clock_s_), newest last; recent_jumps_ of them held.
  std::array<double, FollowParams::kMaxJumpBurstJumps> jump_times_{};
  int recent_jumps_ = 0;
};

}  // namespace duet
