// One user following a duet library, frame by frame (method.md 6, first half of the loop):
// the user's pose -> raw features -> standardised features -> tracker step.
#pragma once

#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "duet/base/result.h"
#include "duet/features/posture_bias.h"
#include "duet/follow/tracker.h"
#include "duet/live/duet_library.h"
#include "duet/live/repeated_frame.h"

namespace duet {

class FollowSession {
 public:
  // user_skeleton/user_roles describe the incoming motion (any convention with the needed roles).
  // The library must outlive the session.
  static Result<FollowSession> create(const DuetLibrary& library,
                                      std::shared_ptr<const Skeleton> user_skeleton,
                                      const JointRoles& user_roles,
                                      std::unique_ptr<Tracker> tracker,
                                      const PostureBiasParams& bias = {});

  // One input frame: local pose of the user's skeleton at time_s (seconds, increasing). The time
  // since the previous frame drives the tracker's rate handling. Allocates nothing. In a grown
  // library (LibraryOptions::grow_to_states) the result's take and frame_in_take are the
  // captured take's (DuetLibrary::place_of); state stays the model's. A frame that repeats the
  // previous one bit for bit reaches the tracker as missing (repeated_frame.h).
  FollowResult step(std::span<const Vec3> translations_ls, std::span<const Quat> rotations_ls,
                    double time_s) noexcept;
  void reset() noexcept;

  // Three points: the head joint's height standing straight (metres, from a height
  // calibration) as the unit of lengths a headset cannot measure
  // (FeatureExtractor::Context::set_head_height). 0, the default, learns it as the highest the
  // head has been, which a dance that starts low gets wrong until the dancer stands. The full-body
  // follower takes the body's size from the skeleton and ignores it. Errors outside
  // kHeadHeightRangeM.
  Status set_head_height(double head_height_m);
  static constexpr double kHeadHeightRangeM[2] = {0.5, 2.5};
  // The calibration's height (0: none) and the three points' unit of lengths in use (the
  // calibration's, else the highest the head has held; 0 before the first frame).
  double known_head_height_m() const noexcept { return context_.known_head_height_m(); }
  double head_height_m() const noexcept { return context_.head_height_m(); }

  // Three points: where the user's wrists are with both arms held straight forward (a body
  // calibration, arms_forward.h). Its difference from the template dancers'
  // (DuetLibrary::template_arms_forward) is the user's body holding every hand elsewhere (wider
  // shoulders, a head further forward), taken off the hands' places
  // (FeatureExtractor::Context::set_hand_offsets); nullopt, the default, takes the hands as they
  // come. The full-body follower ignores it. Errors, and nothing changes, for a pose that
  // ArmsForward::check refuses.
  Status set_arms_forward(const std::optional<ArmsForward>& arms_forward);
  const std::optional<ArmsForward>& arms_forward() const noexcept { return arms_forward_; }
  // Three points: what is taken off each hand's place (head heights, in the head's heading frame):
  // the body calibration's offset (set_arms_forward) plus the posture offset learnt so far on the
  // hands' places (PostureBias, in the features' units back in head heights). Zero for a
  // full-body user. Allocates nothing.
  std::array<Vec3, 2> hand_offsets() const noexcept;

  // Three points: whether the last frame reported hand `side` (0 left, 1 right) where its
  // controller last was, out of the headset's view (FollowResult::partly_observed).
  bool hand_unseen(int side) const noexcept {
    return side >= 0 && side < 2 && hand_held_[static_cast<std::size_t>(side)];
  }
  // The standardised features of the last frame, after the rig's posture offset was removed.
  std::span<const float> last_features() const { return features_; }
  const PostureBias& posture_bias() const { return bias_; }
  const Tracker& tracker() const { return *tracker_; }

 private:
  FollowSession(const DuetLibrary& library, FeatureExtractor extractor,
                std::unique_ptr<Tracker> tracker, const PostureBiasParams& bias,
                RepeatedFrameDetector repeats);
  // A grown library: the estimate's take and frame as the captured take's.
  void report_captured_place(FollowResult& result) noexcept;
  // While lost: looks for a posture offset beyond bias_'s learning gate, and adopts it once the
  // input with it removed has been explained along the dance for a while (offset_search.h).
  void search_offset(const FollowResult& result, double dt_s) noexcept;
  // Three points: marks the dimensions of a hand whose controller repeats its last pose (out of
  // the headset's view) unobserved (NaN), and a hand's speed for the velocity window after it is
  // seen again; the tracker carries them along the dance (HmmForward). Whether it marked any.
  bool mark_unseen_hands(double time_s) noexcept;

  const DuetLibrary* library_;
  FeatureExtractor extractor_;
  FeatureExtractor::Context context_;
  std::unique_ptr<Tracker> tracker_;
  std::vector<float> features_;
  PostureBias bias_;  // the user's rig's posture offset, learnt online
  OffsetSearch search_;                      // an offset beyond bias_'s gate, looked for while lost
  int search_state_ = -1;                    // the template state search_ last matched
  std::optional<ArmsForward> arms_forward_;  // set_arms_forward
  RepeatedFrameDetector repeats_;
  double previous_time_s_ = 0.0;
  bool has_previous_ = false;
  int previous_state_ = -1;  // the estimate of the previous frame
  // Three points: whether each hand's controller repeated its last pose on the previous frame,
  // and when it was last seen again after doing so (mark_unseen_hands).
  std::array<bool, 2> hand_held_{false, false};
  std::array<double, 2> hand_seen_again_at_s_{-std::numeric_limits<double>::infinity(),
                                              -std::numeric_limits<double>::infinity()};
  LibraryPlace previous_place_;  // its captured take and frame (a grown library)
};

}  // namespace duet
