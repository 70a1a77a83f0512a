// A sensor that sends its last frame again (a driver or a network repeating a packet; `duet
// eval`'s `harsh` case repeats 3 % of frames). The repeat is a frame old: as evidence it pulls the
// estimate back to where the dancer was, and its velocity features lag. FollowSession gives the
// tracker such a frame as missing (the band moves on, no emission) and keeps it out of the
// velocities. Only a single repeat is set aside: two or more identical frames in a row are a
// hold (a frozen tracker, or a replay of a held pose), which must still reach the follower as
// evidence, or a user standing still would be run on through the dance.
#pragma once

#include <span>
#include <vector>

#include "duet/math/types.h"

namespace duet {

class RepeatedFrameDetector {
 public:
  // Sized for a skeleton of `joints` joints; a pose of another size is never a repeat.
  explicit RepeatedFrameDetector(int joints = 0);

  // Whether this pose is the previous one again, bit for bit, for the first time (the second copy
  // on is a hold). Remembers the pose. Allocates nothing for poses of the sized joint count.
  bool is_repeat(std::span<const Vec3> translations_ls,
                 std::span<const Quat> rotations_ls) noexcept;
  // Forget the previous pose.
  void reset() noexcept;

 private:
  std::vector<Vec3> translations_;
  std::vector<Quat> rotations_;
  bool has_previous_ = false;
  int copies_ = 0;  // frames since the last new pose that repeated it
};

}  // namespace duet
