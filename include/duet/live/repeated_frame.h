// A sensor that sends its last frame again: a driver or a network repeating a packet (`duet
// eval`'s `harsh` case repeats 3 % of frames), or one that stalls and holds its last pose for
// seconds (a stream that stops updating, a headset that lost tracking: the `stalls` case). A
// copy is no new evidence: as evidence it pulls the estimate back to where the dancer was, its
// velocities read zero, and a held pose matches a take's standing start better than the dance
// (before: `stalls` 87.2 % within 100 ms, 6.2 false jumps a minute; docs/evaluation.md "A sensor
// that stalls"). FollowSession gives the tracker every copy as missing (the band moves on at the
// dancer's tempo, no emission) and keeps it out of the velocities; the tracker reports a stall
// longer than FollowParams::missing_lost_s lost. A real sensor's own noise never gives the same
// pose twice, so a dancer standing still is not a copy. Points each tracked on their own (a
// headset's controllers) stall on their own too: a controller out of the headset's view is
// reported where it was last seen (our viewer sends its last pose), while the head moves on; a
// frame in which one of them repeats is no evidence either (before: the three-point `noise` case
// with a controller held 0.3-2 s every 6 s, 100 -> 91.2 % within 100 ms, 6 false jumps a minute).
#pragma once

#include <span>
#include <vector>

#include "duet/math/types.h"

namespace duet {

class RepeatedFrameDetector {
 public:
  // Sized for a skeleton of `joints` joints; a pose of another size is never a repeat.
  // `tracked_points`: joints each tracked on their own (the head and hands of three points).
  explicit RepeatedFrameDetector(int joints = 0, std::vector<int> tracked_points = {});

  // Whether this pose is the previous one again, bit for bit, or one of the tracked points is.
  // Remembers the pose. Allocates nothing for poses of the sized joint count.
  bool is_repeat(std::span<const Vec3> translations_ls,
                 std::span<const Quat> rotations_ls) noexcept;
  // Whether the last pose given to is_repeat was the previous one again as a whole.
  bool whole_pose_repeated() const noexcept { return whole_; }
  // Whether tracked point `index` (its place in the constructor's list) repeated in the last
  // pose given to is_repeat, while the pose as a whole did not or did.
  bool point_repeated(std::size_t index) const noexcept {
    return index < point_repeated_.size() && point_repeated_[index];
  }
  // Forget the previous pose.
  void reset() noexcept;

 private:
  std::vector<Vec3> translations_;
  std::vector<Quat> rotations_;
  std::vector<int> tracked_points_;  // -1: a point the skeleton does not have
  std::vector<bool> point_repeated_;
  bool whole_ = false;
  bool has_previous_ = false;
};

}  // namespace duet
