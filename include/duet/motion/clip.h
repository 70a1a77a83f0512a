// A clip: a skeleton, a frame rate and, per frame, every joint's local translation and rotation.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "duet/motion/skeleton.h"

namespace duet {

// A pose in local space (_ls): per joint, translation and rotation relative to its parent. The
// root's local transform is its world transform.
struct Pose {
  std::vector<Vec3> translations_ls;
  std::vector<Quat> rotations_ls;

  void resize(int joint_count);
};

// A real frame position between two stored frames: sample `first` and `second` and mix them
// with weight `weight` on `second` (translations lerped, rotations slerped). Per-frame tables that
// are sampled like a clip (SpatialAlignment, HandContacts) use it too.
struct FrameBracket {
  int first = 0;
  int second = 0;
  double weight = 0.0;
};
// `frame` clamped to [0, frame_count - 1] (a non-finite frame gives frame 0); frame_count > 0.
FrameBracket bracket_frame(double frame, int frame_count) noexcept;

class Clip {
 public:
  Clip() = default;
  // Rest pose at every frame (offsets, identity rotations).
  Clip(std::shared_ptr<const Skeleton> skeleton, double frame_rate, int frame_count);

  const Skeleton& skeleton() const { return *skeleton_; }
  std::shared_ptr<const Skeleton> skeleton_ptr() const { return skeleton_; }
  double frame_rate() const { return frame_rate_; }
  void set_frame_rate(double fps) { frame_rate_ = fps; }
  double frame_time() const { return 1.0 / frame_rate_; }
  int frame_count() const { return frame_count_; }
  double duration() const { return frame_count_ / frame_rate_; }
  int joint_count() const { return skeleton_ ? skeleton_->joint_count() : 0; }

  std::span<Vec3> translations_ls(int frame);
  std::span<const Vec3> translations_ls(int frame) const;
  std::span<Quat> rotations_ls(int frame);
  std::span<const Quat> rotations_ls(int frame) const;

  // Copies frame `frame` into `pose` (resized if needed).
  void pose_at(int frame, Pose& pose) const;
  // Pose at a time in seconds: translations lerped, rotations slerped between the two nearest
  // frames; clamped to the clip's ends.
  void sample(double time_s, Pose& pose) const;

  // Multiplies every translation (offsets and animated) by `factor`. Used for unit conversion.
  void scale_lengths(double factor);
  // Drops every frame from `count` on (0 <= count; a count at or over frame_count keeps all).
  void keep_first_frames(int count);

 private:
  std::shared_ptr<const Skeleton> skeleton_;
  double frame_rate_ = 0.0;
  int frame_count_ = 0;
  std::vector<Vec3> translations_ls_;  // frame-major: frame * joint_count + joint
  std::vector<Quat> rotations_ls_;
};

}  // namespace duet
