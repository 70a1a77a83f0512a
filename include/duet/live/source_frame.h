// Sources of the user's motion for the run-time loop (method.md 6): a file replayed in real time,
// a mocap stream, poses sent over the WebSocket. A FrameSource is polled by one thread (the loop);
// it never blocks: the loop asks when the next frame is due (timed sources) or polls after new
// input reached the source (network sources feed it, see source_neuron.h and source_pose.h).
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "duet/motion/arms_forward.h"
#include "duet/motion/skeleton.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

using SteadyClock = std::chrono::steady_clock;

// What a source delivers: the user's skeleton (offsets in metres), its joint roles, the scale from
// the stream's length units to metres, and its nominal frame rate (live frames carry their own
// times; the rate is what recordings are written at).
struct SourceSkeleton {
  std::shared_ptr<const Skeleton> skeleton;
  JointRoles roles;
  double metres_per_unit = 1.0;
  double frame_rate = 60.0;
  // Three points: the head joint's height (metres above the floor) with the user standing
  // straight, when a height calibration gave it (a headset says nothing of the body's size); 0:
  // learnt from the input (FollowSession::set_head_height).
  double head_height_m = 0.0;
  // Three points: where the user's wrists are with both arms held straight forward, when a body
  // calibration gave it (FollowSession::set_arms_forward); nullopt: the hands as they come.
  std::optional<ArmsForward> arms_forward = std::nullopt;

  int joint_count() const { return skeleton ? skeleton->joint_count() : 0; }
};

// One frame of the user's motion: the local pose of the source skeleton, the performance time
// that drives the follower, and when the frame reached us (where latency is measured from).
// Buffers are sized once (resize) and then overwritten in place.
struct SourceFrame {
  double time_s = 0.0;                // seconds, increasing; the source's clock
  SteadyClock::time_point arrival{};  // when the frame became available
  std::vector<Vec3> translations_ls;
  std::vector<Quat> rotations_ls;

  void resize(int joint_count);
};

struct SourceStats {
  long long frames = 0;    // frames delivered by poll()
  long long rejected = 0;  // input that made no frame: bad lines, bad poses
  long long dropped = 0;   // frames that arrived but were never delivered (overflow, catch-up)
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  virtual const SourceSkeleton& source_skeleton() const noexcept = 0;
  // "replay 60_03_scaled.bvh at 1x", "Perception Neuron TCP 127.0.0.1:7001", ...
  virtual std::string describe() const = 0;

  // Starts the source's clock (timed sources); called once before the first poll.
  virtual void start(SteadyClock::time_point /*now*/) noexcept {}
  // Timed sources: when the next frame is due. Input-driven sources: nullopt.
  virtual std::optional<SteadyClock::time_point> next_due() const noexcept { return std::nullopt; }
  // Copies the next available frame (due at or before `now`) into `out`, whose buffers have the
  // skeleton's joint count. Returns false when there is none. Allocates nothing.
  virtual bool poll(SteadyClock::time_point now, SourceFrame& out) noexcept = 0;
  // No frame will ever come again (a replay that does not loop has played its last frame).
  virtual bool finished() const noexcept { return false; }

  virtual SourceStats stats() const noexcept = 0;

 protected:
  FrameSource() = default;
  FrameSource(const FrameSource&) = default;
  FrameSource& operator=(const FrameSource&) = default;
};

// A bounded FIFO of frames with preallocated slots, for sources fed by network input. When it is
// full the oldest frame is overwritten (a live loop wants the newest motion) and counted as
// dropped. Single-threaded: the thread that feeds it also polls it.
class FrameQueue {
 public:
  FrameQueue(int joint_count, int capacity);

  // Two-step push without copying: fill the slot begin_push() returns, then commit_push(). A slot
  // that is not committed is reused by the next begin_push().
  SourceFrame& begin_push() noexcept;
  void commit_push() noexcept;

  bool pop(SourceFrame& out) noexcept;
  int size() const noexcept { return size_; }
  int capacity() const noexcept { return static_cast<int>(slots_.size()) - 1; }
  long long dropped() const noexcept { return dropped_; }
  void clear() noexcept { head_ = size_ = 0; }

 private:
  std::vector<SourceFrame> slots_;
  int head_ = 0;  // oldest
  int size_ = 0;
  long long dropped_ = 0;
};

}  // namespace duet
