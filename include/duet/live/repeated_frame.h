// A sensor that sends its last frame again: a driver or a network repeating a packet (`duet
// eval`'s `harsh` case repeats 3 % of frames), or one that stalls and holds its last pose for
// seconds (a stream that stops updating, a headset that lost tracking: the `stalls` case). A
// copy is no new evidence: as evidence it pulls the estimate back to where the dancer was, its
// velocities read zero, and a held pose matches a take's standing start better than the dance
// (before: `stalls` 87.2 % within 100 ms, 6.2 false jumps a minute; docs/evaluation.md "A sensor
// that stalls"). FollowSession gives the tracker every copy as missing (the band moves on at the
// dancer's tempo, no emission) and keeps it out of the velocities; the tracker reports a stall
// longer than FollowParams::missing_lost_s lost. A real sensor's own noise never gives the same
// pose twice, so a dancer standing still is not a copy.
#pragma once

#include <span>
#include <vector>

#include "duet/math/types.h"

namespace duet {

class RepeatedFrameDetector {
 public:
  // Sized for a skeleton of `joints` joints; a pose of another size is never a repeat.
  explicit RepeatedFrameDetector(int joints = 0);

  // Whether this pose is the previous one again, bit for bit. Remembers the pose. Allocates
  // nothing for poses of the sized joint count.
  bool is_repeat(std::span<const Vec3> translations_ls,
                 std::span<const Quat> rotations_ls) noexcept;
  // Forget the previous pose.
  void reset() noexcept;

 private:
  std::vector<Vec3> translations_;
  std::vector<Quat> rotations_;
  bool has_previous_ = false;
};

}  // namespace duet
