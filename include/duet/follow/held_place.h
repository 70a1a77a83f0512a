// How long the follower's estimate has held one place of the library.
//
// A dance moves on: the template's frames pass at the dancer's tempo, and no salsa take holds a
// pose for seconds. An input the follower pins to one frame for long, a person standing with the
// hands hanging, matches a take's first standing frames as closely as any dance matches its take,
// yet no part of the library explains it: the Bandai dance's first 8.5 s as three points were
// followed at frame 49 of take 60_05 the whole time (FollowParams::held_place_lost_s).
#pragma once

namespace duet {

class HeldPlace {
 public:
  // The frame's estimate (a template state; negative: none), whether the follower called a jump,
  // and the frame's input time. A move of `reach_states` or more from where the hold began (either
  // way), or a jump, starts a new hold there.
  void update(int state, bool jumped, double dt_s, int reach_states) noexcept;
  // Input time the estimate has held within reach of where the hold began.
  double held_s() const noexcept { return held_s_; }
  void reset() noexcept {
    anchor_ = -1;
    held_s_ = 0.0;
  }

 private:
  int anchor_ = -1;  // the state the hold began at
  double held_s_ = 0.0;
};

// Whether the estimate still stands where the follower found a place again after a spell lost.
//
// Motion no take holds passes through poses a dance holds: the Bandai wave's arm coming down
// leaves a person standing, hands hanging, which three points cannot tell from a salsa take's
// standing start. Found again there, the estimate stays put; a dancer found again moves on with
// the dance at once (FollowParams::found_still_spell_s).
class StillSinceFound {
 public:
  // The frame's estimate (a template state; negative: none), whether the follower called a jump,
  // and, on the frame the follower found a place again after a long enough spell lost, the
  // estimate where the input first came back within reach of the library (the found-again wait
  // began; negative on every other frame). A move of `reach_states` or more from there (either
  // way), or a jump after that frame, ends the stillness: a dancer moved on during the wait is
  // no person standing.
  void update(int state, bool jumped, int found_again_from, int reach_states) noexcept;
  // Whether the estimate has not moved on since it was found again.
  bool still() const noexcept { return found_at_ >= 0; }
  void reset() noexcept { found_at_ = -1; }

 private:
  int found_at_ = -1;  // the state the place was found again at; negative: moved on, or none
};

}  // namespace duet
