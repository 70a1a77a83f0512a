// The run-time loop of method.md 6, one input frame at a time:
//
//   user's local pose -> features -> forward step -> estimated state
//   -> response pose at that state -> alignment -> smoothing -> foot lock -> hand IK -> blend
//   -> world transforms of both dancers
//
// LiveLoop owns everything the loop needs (follow session, partner models, partner context, output
// buffers), all sized when it is created. step() allocates nothing, throws nothing and does no
// I/O. Threads, sockets and files are the caller's (the net layer, the recorder).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "duet/base/result.h"
#include "duet/live/duet_library.h"
#include "duet/live/follow_session.h"
#include "duet/live/partner_place.h"
#include "duet/live/source_frame.h"
#include "duet/live/unseen_user.h"
#include "duet/live/wrists_on_user_body.h"
#include "duet/partner/head_hands_body.h"
#include "duet/partner/partner_synthesis.h"

namespace duet {

// What one frame of the loop produced. Buffers are sized once and overwritten by every step().
struct LiveOutput {
  long long seq = -1;   // frames processed since the loop was created (0 for the first)
  double time_s = 0.0;  // the input frame's time
  FollowResult follow;
  // The user's left / right hand holds the partner's at the estimated template frame, as
  // captured (whether or not the contact correction is on).
  bool contact_left = false;
  bool contact_right = false;
  PartnerFrameInfo partner_info;
  int partner_take = 0;              // the take whose response the partner pose comes from
  int partner_frame = 0;             // and its frame (the playhead's, rounded)
  bool partner_synthesised = false;  // false: the raw response pose (the job could not run)

  // World transforms of the user's skeleton (the source's) and of the partner's.
  std::vector<Vec3> user_positions_ws;
  std::vector<Quat> user_rotations_ws;
  // The partner's local pose (root in the user's world frame when align is on) and world pose.
  std::vector<Vec3> partner_translations_ls;
  std::vector<Quat> partner_rotations_ls;
  std::vector<Vec3> partner_positions_ws;
  std::vector<Quat> partner_rotations_ws;
};

class LiveLoop {
 public:
  // Builds the partner model of every take (offline: allocates, may fail) and sizes every buffer.
  // Every take's response skeleton must have the same joints (names and parents), so the partner
  // is one skeleton whatever take the follower is in. The library is shared, so a loop can be
  // handed between threads and kept alive as long as needed.
  static Result<LiveLoop> create(std::shared_ptr<const DuetLibrary> library,
                                 const SourceSkeleton& user, std::unique_ptr<Tracker> tracker,
                                 const PartnerParams& params = {},
                                 const PartnerModelOptions& model_options = {});

  // One input frame (buffers sized to the user's joint count). Returns the output, which stays
  // valid until the next step(). Allocates nothing.
  const LiveOutput& step(const SourceFrame& frame) noexcept;

  // Restart the follower and the corrections' state (the next frame starts fresh).
  void reset() noexcept;
  // Three points: the head joint's height standing, from a height calibration
  // (SourceSkeleton::head_height_m); 0 learns it again. Errors, and nothing changes, outside
  // FollowSession::kHeadHeightRangeM. Call between steps, as the other setters.
  Status set_head_height(double head_height_m);
  double head_height_m() const noexcept { return session_.known_head_height_m(); }
  // Three points: where the user's wrists are with both arms held straight forward
  // (SourceSkeleton::arms_forward); nullopt forgets it. Errors, and nothing changes, for a pose
  // FollowSession::set_arms_forward refuses.
  Status set_arms_forward(const std::optional<ArmsForward>& arms_forward);
  const std::optional<ArmsForward>& arms_forward() const noexcept {
    return session_.arms_forward();
  }
  // Switch a correction (protocol name); false for an unknown name.
  bool set_correction(std::string_view name, bool enabled) noexcept;
  void set_params(const PartnerParams& params) noexcept { params_ = params; }
  const PartnerParams& params() const noexcept { return params_; }

  const DuetLibrary& library() const noexcept { return *library_; }
  DancerRole role() const noexcept { return library_->options().role; }
  const SourceSkeleton& user() const noexcept { return user_; }
  // The partner's skeleton as sent to viewers and recorded (take 0's response skeleton).
  std::shared_ptr<const Skeleton> partner_skeleton() const noexcept;
  // The user's height the partner's spacing was fitted to on the last step (the skeleton's
  // standing height; three points: from the head's height, FollowSession::head_height_m).
  double user_height_m() const noexcept { return user_pose_.height_m; }
  const PartnerModel& partner_model(int take) const noexcept {
    return models_[static_cast<std::size_t>(take)];
  }
  const LiveOutput& output() const noexcept { return out_; }

 private:
  LiveLoop(std::shared_ptr<const DuetLibrary> library, const SourceSkeleton& user,
           FollowSession session, std::vector<PartnerModel> models, const PartnerParams& params);
  // A user tracked by three points: their body heading frame and height, from the head and the
  // template frame `frame` of `take` (HeadHandsBody).
  void place_head_hands_user(int take, int frame) noexcept;
  // A user tracked by three points: where their body puts each wrist beyond the template
  // dancer's at the partner's frame `position` of `take`, in the body heading frame
  // (UserPose::wrist_body_difference_hs): their size, and the hands' offset the follower takes
  // off (FollowSession::hand_offsets).
  std::array<Vec3, 2> head_hands_wrist_difference_hs(int take, double position) const noexcept;

  std::shared_ptr<const DuetLibrary> library_;
  SourceSkeleton user_;
  FollowSession session_;
  std::vector<PartnerModel> models_;  // one per take
  PartnerParams params_;
  PartnerContext context_;
  LiveOutput out_;
  UserPose user_pose_;
  double user_height_m_ = 0.0;  // measure_body of the user's skeleton: fits the partner's spacing
  // Per take, the user's hand frames turned into the template's (hand_frame_turns), where the
  // grip offsets are held.
  std::vector<std::array<Quat, 2>> hand_frame_turns_;
  // Three-point users (head and hands only): one HeadHandsBody per take; empty for a full body.
  std::vector<HeadHandsBody> head_hands_bodies_;
  double head_hands_size_ratio_ = 0.0;  // this frame's user size against the template's; 0: none
  // Full body: where the user's own body puts the wrists (the contact IK's expected difference).
  std::optional<WristsOnUserBody> wrists_on_user_body_;
  Quat device_correction_ = Quat::Identity();  // a point's device rotation -> canonical
  ResponsePlayhead playhead_;
  Pose shown_pose_;  // the response sampled at the playhead
  PartnerPlace place_;  // where in the library the partner dances
  UnseenUser unseen_user_;  // the user carried on through frames without evidence
  double previous_time_s_ = 0.0;
  bool has_previous_ = false;
};

}  // namespace duet
