#include "duet/live/follow_session.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <utility>

#include "duet/live/lost_confidence.h"
#include "duet/live/young_offset_confidence.h"
#include "duet/motion/head_hands.h"

namespace duet {

namespace {

// The three points' places in the repeat detector's list of points tracked on their own: the
// head, then the left and right wrists (side 0 and 1, as FeatureSpec::hand_point_dims).
constexpr std::size_t kHeadPoint = 0;
constexpr std::size_t hand_point(std::size_t side) { return 1 + side; }

}  // namespace

Result<FollowSession> FollowSession::create(const DuetLibrary& library,
                                            std::shared_ptr<const Skeleton> user_skeleton,
                                            const JointRoles& user_roles,
                                            std::unique_ptr<Tracker> tracker,
                                            const PostureBiasParams& bias) {
  if (!tracker) return Error{"follow session: no tracker"};
  const int joints = user_skeleton ? user_skeleton->joint_count() : 0;
  Result<FeatureExtractor> extractor = library.make_extractor(std::move(user_skeleton), user_roles);
  if (!extractor) return Error{"the user's motion: " + extractor.error().message};
  // Three points are tracked each on its own: one may stall while the others move on.
  std::vector<int> tracked_points;
  if (is_head_hands_input(user_roles)) {
    tracked_points = {user_roles[Role::kHead], user_roles[Role::kLeftWrist],
                      user_roles[Role::kRightWrist]};  // kHeadPoint, hand_point(0), hand_point(1)
  }
  return FollowSession(library, std::move(extractor).value(), std::move(tracker), bias,
                       RepeatedFrameDetector(joints, std::move(tracked_points)));
}

FollowSession::FollowSession(const DuetLibrary& library, FeatureExtractor extractor,
                             std::unique_ptr<Tracker> tracker, const PostureBiasParams& bias,
                             RepeatedFrameDetector repeats)
    : library_(&library),
      extractor_(std::move(extractor)),
      context_(extractor_.make_context()),
      tracker_(std::move(tracker)),
      features_(static_cast<std::size_t>(extractor_.dimension())),
      bias_(extractor_.spec().block_begin(FeatureBlock::kPosture),
            extractor_.spec().block_size(FeatureBlock::kPosture),
            posture_bias_params_for(extractor_.spec().input_points, bias)),
      search_(extractor_.spec().block_begin(FeatureBlock::kPosture),
              extractor_.spec().block_size(FeatureBlock::kPosture), extractor_.dimension()),
      repeats_(std::move(repeats)) {}

FollowResult FollowSession::step(std::span<const Vec3> translations_ls,
                                 std::span<const Quat> rotations_ls, double time_s) noexcept {
  const bool repeat = repeats_.is_repeat(translations_ls, rotations_ls);
  // Three points: a controller out of the headset's view repeats its last pose while the head
  // moves on. The head and the other hand are still evidence (mark_unseen_hands).
  const bool only_hands_repeat =
      repeat && extractor_.spec().input_points == InputPoints::kHeadHands &&
      !repeats_.whole_pose_repeated() && !repeats_.point_repeated(kHeadPoint);
  if (repeat && !only_hands_repeat) {
    // No new evidence, and kept out of the velocities: the tracker moves its band on.
    std::ranges::fill(features_, std::numeric_limits<float>::quiet_NaN());
  } else {
    extractor_.extract(context_, translations_ls, rotations_ls, time_s, features_);
    library_->normalizer().apply(features_);
  }
  const double dt_s = has_previous_ ? time_s - previous_time_s_ : 0.0;
  if (std::isfinite(time_s)) {
    previous_time_s_ = time_s;
    has_previous_ = true;
  }
  bias_.correct(features_);
  const bool partly_unseen = mark_unseen_hands(time_s);
  FollowResult result = tracker_->step(features_, dt_s);
  // Learn only from frames the library explains well: a motion that is no dance (a walk) must
  // stay lost, not teach the offset that would make it look like one. A step of the estimate
  // backwards (jitter the follower does not call a jump) says the match is off by a frame or
  // two in the direction of motion: it teaches nothing either. The distance test is the
  // session's own, not the tracker's lost flag: the HMM's noise-scaled lost level is below it on
  // a clean sensor, and learning from fewer frames cost 0.3 points at 0.7x tempo. (A frame the
  // follower set aside as an outlier still teaches: kept out, the Bandai wave looped as three
  // points was lost on 94.8 % of its frames, not 96.1; docs/evaluation.md, "A sensor that pops".)
  const bool same_take =
      previous_state_ >= 0 && library_->model().take_of(previous_state_) == result.take;
  const bool stepped_back = same_take && result.state < previous_state_;
  // A far move the follower does not call a jump (the first placement being refined) says the
  // previous frames' match was elsewhere: the frame teaches nothing either.
  constexpr int kFarFrames = 12;
  const bool moved_unreported =
      previous_state_ >= 0 && !result.jumped &&
      (!same_take || std::abs(result.state - previous_state_) > kFarFrames);
  previous_state_ = result.state;
  if (!result.jumped && !stepped_back && !moved_unreported && !result.missing && !partly_unseen &&
      !result.in_pause &&
      result.best_distance_per_dim <=
          bias_.params().learn_distance_limit(result.sensor_noise_per_dim) &&
      result.state >= 0 && result.state < library_->model().num_states()) {
    const auto& rows = library_->model().features();
    bias_.learn(features_,
                std::span<const float>(rows.row(result.state).data(),
                                       static_cast<std::size_t>(rows.cols())),
                dt_s, result.confidence, result.sensor_noise_per_dim);
  }
  if (!partly_unseen) search_offset(result, dt_s);
  // A frame without evidence neither breaks nor extends a lost run.
  if (!result.missing) bias_.note_lost(result.lost && !result.still_since_lost, dt_s);
  result.rig_offset = bias_.offset_rms();
  result.rig_offset_learnt_s = static_cast<float>(bias_.learnt_s());
  result.tracker_confidence = result.confidence;
  if (bias_.params().enabled && bias_.params().young_offset_confidence) {
    result.confidence =
        YoungOffsetConfidence::apply(result.confidence, result.rig_offset,
                                     result.rig_offset_learnt_s, extractor_.spec().input_points);
  }
  if (result.lost && bias_.params().lost_confidence) {
    result.confidence = LostConfidence::apply(result.confidence, extractor_.spec().input_points);
  }
  if (library_->grown()) report_captured_place(result);
  return result;
}

bool FollowSession::mark_unseen_hands(double time_s) noexcept {
  if (extractor_.spec().input_points != InputPoints::kHeadHands || !std::isfinite(features_[0]) ||
      !std::isfinite(time_s)) {
    return false;
  }
  bool marked = false;
  constexpr float kUnseen = std::numeric_limits<float>::quiet_NaN();
  for (int side = 0; side < 2; ++side) {
    const auto s = static_cast<std::size_t>(side);
    const std::array<int, 4> dims = extractor_.spec().hand_point_dims(side);
    if (repeats_.point_repeated(hand_point(s))) {
      for (const int d : dims) features_[static_cast<std::size_t>(d)] = kUnseen;
      hand_held_[s] = true;
      marked = true;
      continue;
    }
    if (hand_held_[s]) {
      hand_held_[s] = false;
      hand_seen_again_at_s_[s] = time_s;
    }
    // Seen again: until the first frame seen again is old enough to be the speed's reference
    // sample (FeatureExtractor::velocity_reference), the speed is a difference from the place the
    // hand was held at.
    if (time_s - hand_seen_again_at_s_[s] < extractor_.spec().velocity_window_s) {
      features_[static_cast<std::size_t>(dims[3])] = kUnseen;
      marked = true;
    }
  }
  return marked;
}

void FollowSession::search_offset(const FollowResult& result, double dt_s) noexcept {
  const PostureBiasParams& params = bias_.params();
  const TemplateModel& model = library_->model();
  // Only while the input is unexplained (the pause state holds it, or it is lost) and no offset of
  // size is held (a held one is let go after release_after_lost_s lost; the search starts then).
  if (!params.enabled || !params.search.enabled ||
      !(result.in_pause || (result.lost && !result.still_since_lost)) || result.missing ||
      result.state < 0 || result.state >= model.num_states() ||
      bias_.offset_rms() > params.release_offset_rms) {
    if (!result.missing) {
      search_.reset();
      search_state_ = -1;
    }
    return;
  }
  // The matched frames follow one another as a dance does: within the take, forward by up to the
  // band's reach, or back by a few frames of jitter.
  constexpr int kJitterFrames = 6;
  const bool continues =
      search_state_ >= 0 &&
      !model.is_jump(search_state_, result.state, std::max(result.steps, 1), kJitterFrames);
  search_state_ = result.state;
  const auto& rows = model.features();
  const std::span<const float> matched(rows.row(result.state).data(),
                                       static_cast<std::size_t>(rows.cols()));
  if (search_.observe(features_, matched, continues,
                      params.learn_distance_limit(result.sensor_noise_per_dim), dt_s,
                      params.search)) {
    bias_.adopt(search_.offset(), search_.held_s());
    search_.reset();
    search_state_ = -1;
  }
}

void FollowSession::report_captured_place(FollowResult& result) noexcept {
  if (result.take < 0) return;
  const LibraryPlace place = library_->place_of(result.take, result.frame_in_take);
  // Copies of one take at other speeds hold the same moment at nearby frames: a move between
  // them that lands within a few frames of the previous place is no jump for the partner.
  constexpr int kSamePlaceFrames = 8;
  if (result.jumped && previous_place_.take == place.take &&
      std::abs(place.frame - previous_place_.frame) <= kSamePlaceFrames) {
    result.jumped = false;
  }
  // A copy's frames are not the captured take's: its place between frames is not known there.
  if (place.take != result.take) result.frame_offset = 0.0f;
  result.take = place.take;
  result.frame_in_take = place.frame;
  previous_place_ = place;
}

Status FollowSession::set_head_height(double head_height_m) {
  if (head_height_m != 0.0 &&
      !(head_height_m >= kHeadHeightRangeM[0] && head_height_m <= kHeadHeightRangeM[1])) {
    return Error{
        fmt::format("head height {:g} m: give the head's height standing in metres, {:g} to {:g}",
                    head_height_m, kHeadHeightRangeM[0], kHeadHeightRangeM[1])};
  }
  context_.set_head_height(head_height_m);
  return Ok{};
}

Status FollowSession::set_arms_forward(const std::optional<ArmsForward>& arms_forward) {
  std::array<Vec3, 2> offsets{Vec3::Zero(), Vec3::Zero()};
  if (arms_forward) {
    if (std::string problem = arms_forward->check(); !problem.empty()) {
      return Error{"arms held forward: " + problem};
    }
    const ArmsForward& library_pose = library_->template_arms_forward();
    for (std::size_t side = 0; side < 2; ++side) {
      offsets[side] = arms_forward->wrists[side] - library_pose.wrists[side];
    }
  }
  // A full-body library's features have no hand places: the offsets stay unused.
  context_.set_hand_offsets(offsets);
  arms_forward_ = arms_forward;
  return Ok{};
}

std::array<Vec3, 2> FollowSession::hand_offsets() const noexcept {
  std::array<Vec3, 2> offsets = context_.hand_offsets();
  if (extractor_.spec().input_points != InputPoints::kHeadHands || !bias_.params().enabled) {
    return offsets;
  }
  // The posture block starts with the two hands' places (FeatureExtractor: left, then right).
  const int begin = extractor_.spec().block_begin(FeatureBlock::kPosture);
  const std::span<const float> learnt = bias_.offset();
  const Eigen::VectorXf& scale = library_->normalizer().scale();
  for (std::size_t s = 0; s < 2; ++s) {
    for (int k = 0; k < 3; ++k) {
      const std::size_t d = 3 * s + static_cast<std::size_t>(k);
      const Eigen::Index at = begin + static_cast<Eigen::Index>(d);
      if (d < learnt.size() && at < scale.size() && scale[at] > 0.0f) {
        offsets[s][k] += static_cast<double>(learnt[d] / scale[at]);
      }
    }
  }
  return offsets;
}

void FollowSession::reset() noexcept {
  context_.reset();
  tracker_->reset();
  bias_.reset();
  search_.reset();
  search_state_ = -1;
  repeats_.reset();
  has_previous_ = false;
  previous_state_ = -1;
  previous_place_ = {};
  hand_held_ = {false, false};
  hand_seen_again_at_s_.fill(-std::numeric_limits<double>::infinity());
}

}  // namespace duet
