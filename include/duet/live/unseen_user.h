// Where the user is while the sensor says nothing new (issue 11, "A sensor that stalls").
//
// A stalled sensor (a stream that stops updating, a headset that lost tracking and reports its
// last pose) or a frame without a usable pose gives the follower no evidence: the tempo carries
// its estimate on (FollowParams::missing_lost_s). The partner, though, is placed relative to the
// user's body and joins the user's hands; taken from the held pose, the user stood frozen where
// last seen while the partner danced on, and was found at once somewhere else when the sensor
// came back. The dancer dances on: while unseen, the user is carried from where they were last
// seen as the template dancer moves between the two frames of the dance (the template's body
// heading frame at each, its steps scaled to the user's size), body heading, root and hands
// alike. Allocates nothing.
#pragma once

#include <array>

#include "duet/math/types.h"
#include "duet/partner/partner_synthesis.h"

namespace duet {

class UnseenUser {
 public:
  // A frame with evidence: remember the user and the template's heading frame at the partner's
  // frame (`take`), its translation already scaled to the user's size.
  void seen(const UserPose& user, const Transform& template_heading, int take) noexcept;
  // A frame without: move `user` (the held or missing pose) to where the last seen user has gone
  // as the template's heading went from the remembered frame to `template_heading`. False (and
  // `user` unchanged) before any frame was seen, or in another take than the one last seen in
  // (a jump while unseen: nothing says how the user got there).
  bool carry(UserPose& user, const Transform& template_heading, int take) const noexcept;
  // A frame with the body seen but some hands not (three points, a controller out of the
  // headset's view, which reports where it was): each unseen hand held where it was last seen
  // against the body's heading frame, on the body as seen now (what `carry` does to a hand, less
  // the body's move, which is seen). False (and `user` unchanged) before any frame was seen.
  // Then call `seen` with the result: a hand unseen for longer stays where it was.
  bool hold_hands(UserPose& user, const std::array<bool, 2>& unseen) const noexcept;
  void reset() noexcept { take_ = -1; }

 private:
  UserPose last_;
  Transform template_heading_;
  int take_ = -1;
};

}  // namespace duet
