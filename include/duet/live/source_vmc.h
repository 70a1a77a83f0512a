// A VMC stream (Virtual Motion Capture protocol, OSC over UDP: XR Animator, SlimeVR, VSeeFace,
// Warudo, ...) as a frame source. The network side decodes the OSC packets (net/vmc_receiver.h)
// and hands over the messages this source understands; the source turns them into local poses of
// the VMC humanoid (vmc_humanoid.h):
//
//   /VMC/Ext/Root/Pos s name, f px py pz, f qx qy qz qw [, ...]   the avatar's root transform
//   /VMC/Ext/Bone/Pos s HumanBodyBones name, f px py pz, f qx qy qz qw   a bone's local transform
//   /VMC/Ext/OK i loaded [, ...]                                 end of a frame
//   /VMC/Ext/T f time                                            end of a frame
//
// in Unity's axes (converted, see vmc_humanoid.h). A bone's rotation is taken as sent; its
// position only for the Hips (the body's place; the other bones keep the humanoid's lengths). A
// frame is complete at the first OK or T after bone data (performers send both, OK first), or at
// the end of a packet for a sender that never sent either. Bones a frame does not mention keep
// their last rotation. Frame times are arrival times (seconds since the first frame).
//
// Nothing from the network is trusted: a non-finite number, a position further than 1 km, a
// quaternion far from unit length is a rejected message (counted); a bone VMC names that the
// humanoid lacks (fingers, eyes) and VMC messages the follower does not read (blend shapes,
// camera, trackers) are ignored (counted apart). Allocates nothing after construction.
#pragma once

#include <string>
#include <string_view>

#include "duet/live/source_frame.h"

namespace duet {

struct VmcStreamOptions {
  int queue_frames = 8;  // frames kept between polls; older ones are dropped on overflow
};

enum class VmcReject {
  kNone,
  kMalformed,     // not OSC: a bad bundle or message (decided by the receiver)
  kForeign,       // OSC, but not a /VMC/ address
  kBadArguments,  // a VMC address with the wrong argument types or count
  kNonFinite,     // a number that is nan or inf, or a position further than 1 km
  kBadRotation,   // a quaternion far from unit length
};
const char* vmc_reject_name(VmcReject reason);

class VmcSource final : public FrameSource {
 public:
  VmcSource(const VmcStreamOptions& options, std::string name, double frame_rate = 60.0);

  // Messages, in the order they arrive (positions and rotations in Unity's axes, as sent).
  void root(const Vec3& position, const Quat& rotation) noexcept;
  void bone(std::string_view name, const Vec3& position, const Quat& rotation) noexcept;
  // /VMC/Ext/OK or /VMC/Ext/T.
  void frame_marker(SteadyClock::time_point arrival) noexcept;
  // A VMC message the follower does not use.
  void ignore() noexcept { ++ignored_; }
  // Input that could not be used; counted in stats().rejected.
  void reject(VmcReject reason) noexcept;
  // The end of one UDP datagram.
  void end_packet(SteadyClock::time_point arrival) noexcept;

  const SourceSkeleton& source_skeleton() const noexcept override { return skeleton_; }
  std::string describe() const override { return name_; }
  bool poll(SteadyClock::time_point now, SourceFrame& out) noexcept override;
  SourceStats stats() const noexcept override;

  long long ignored() const noexcept { return ignored_; }
  VmcReject last_rejection() const noexcept { return last_rejection_; }

 private:
  bool check(const Vec3& position, const Quat& rotation, Quat& unit) noexcept;
  void emit(SteadyClock::time_point arrival) noexcept;

  SourceSkeleton skeleton_;
  std::string name_;
  FrameQueue queue_;
  SourceFrame current_;  // the pose as the messages so far describe it (Duet axes)
  Vec3 root_position_ = Vec3::Zero();
  Quat root_rotation_ = Quat::Identity();
  Vec3 hips_position_ = Vec3::Zero();  // relative to the root, Duet axes
  bool dirty_ = false;                 // bone or root data since the last frame
  bool seen_marker_ = false;           // the sender ends frames with OK or T
  bool have_epoch_ = false;
  SteadyClock::time_point epoch_{};
  SourceStats stats_;
  long long ignored_ = 0;
  VmcReject last_rejection_ = VmcReject::kNone;
};

}  // namespace duet
