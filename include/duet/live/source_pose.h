// Poses sent over the WebSocket (`--source ws`, the `pose` message of docs/protocol.md): per frame,
// the root position in metres and the local rotation of every joint of the source skeleton (in
// its joint order, End Sites included; their rotations are ignored). The network layer decodes
// the JSON; this source validates the numbers and queues the frame.
#pragma once

#include <string>

#include "duet/base/result.h"
#include "duet/live/source_frame.h"
#include "duet/motion/device_points.h"

namespace duet {

struct PoseSourceOptions {
  int queue_frames = 8;  // frames kept between polls; older ones are dropped on overflow
  // Three points: where the devices sit against the joints, taken out of every xr_pose.
  DevicePointOffsets device_offsets;
};

class PoseSource final : public FrameSource {
 public:
  PoseSource(SourceSkeleton skeleton, const PoseSourceOptions& options, std::string name);

  // One pose. `rotations_wxyz` holds 4 numbers per joint (w, x, y, z), `time_s` the sender's
  // clock in seconds (NaN: use the arrival time). Rejects (returns false, counts, and says why in
  // `reason`) a pose whose joint count is wrong, whose numbers are not finite, whose quaternions
  // are far from unit length (0.5 < |q| < 2; others are normalised) or whose root is further than
  // 1 km from the origin. Allocates nothing on success; `reason` only on failure.
  bool push(double time_s, const Vec3& root_position, std::span<const double> rotations_wxyz,
            SteadyClock::time_point arrival, std::string& reason) noexcept;

  // Three points (the `xr_pose` message; the source's skeleton must be the head-and-hands one,
  // duet/motion/head_hands.h): head, left and right hand positions in metres (within 1 km) and
  // orientations, 4 numbers each (w, x, y, z), moved from the devices to the joints by the
  // options' device_offsets. Same checks and queueing as push().
  bool push_points(double time_s, std::span<const Vec3> positions,
                   std::span<const double> orientations_wxyz, SteadyClock::time_point arrival,
                   std::string& reason) noexcept;

  const SourceSkeleton& source_skeleton() const noexcept override { return skeleton_; }
  const DevicePointOffsets& device_offsets() const noexcept { return device_offsets_; }
  std::string describe() const override { return name_; }
  bool poll(SteadyClock::time_point now, SourceFrame& out) noexcept override;
  SourceStats stats() const noexcept override;

 private:
  SourceSkeleton skeleton_;
  std::string name_;
  FrameQueue queue_;
  DevicePointOffsets device_offsets_;
  bool have_epoch_ = false;
  SteadyClock::time_point epoch_{};
  SourceStats stats_;

  bool reject(const char* why, std::string& reason) noexcept;
  // Stamps and queues the frame begun in `slot`.
  void commit(SourceFrame& slot, double time_s, SteadyClock::time_point arrival) noexcept;
};

}  // namespace duet
