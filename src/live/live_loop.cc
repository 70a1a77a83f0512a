#include "duet/live/live_loop.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"

namespace duet {

namespace {

// Same joints (names and parents) in the same order.
bool same_joints(const Skeleton& a, const Skeleton& b) {
  if (a.joint_count() != b.joint_count()) return false;
  for (std::size_t j = 0; j < a.joints.size(); ++j) {
    if (a.joints[j].name != b.joints[j].name || a.joints[j].parent != b.joints[j].parent) {
      return false;
    }
  }
  return true;
}

}  // namespace

Result<LiveLoop> LiveLoop::create(std::shared_ptr<const DuetLibrary> library,
                                  const SourceSkeleton& user, std::unique_ptr<Tracker> tracker,
                                  const PartnerParams& params,
                                  const PartnerModelOptions& model_options) {
  if (!library || library->takes().empty()) return Error{"live loop: no duet library"};
  if (!user.skeleton || user.skeleton->joint_count() == 0) {
    return Error{"live loop: the source has no skeleton"};
  }
  if (const std::string problem = params.validate(); !problem.empty()) {
    return Error{"live loop: " + problem};
  }
  const Skeleton& first = library->takes()[0].response_motion.clip.skeleton();
  std::vector<PartnerModel> models;
  models.reserve(library->takes().size());
  for (const DuetTake& take : library->takes()) {
    const Clip& response = take.response_motion.clip;
    if (!same_joints(response.skeleton(), first)) {
      return Error{"live loop: take " + take.name +
                   ": the partner's skeleton differs from the first take's; every partner file of "
                   "a library must share one skeleton"};
    }
    Result<PartnerModel> model =
        PartnerModel::build(take.template_motion.clip, take.template_motion.roles, response,
                            take.response_motion.roles, model_options);
    if (!model) return Error{"take " + take.name + ": " + model.error().message};
    models.push_back(std::move(model).value());
  }
  Result<FollowSession> session =
      FollowSession::create(*library, user.skeleton, user.roles, std::move(tracker));
  if (!session) return session.error();
  if (Status s = session.value().set_head_height(user.head_height_m); !s) return s.error();
  if (Status s = session.value().set_arms_forward(user.arms_forward); !s) return s.error();
  std::vector<HeadHandsBody> head_hands_bodies;
  if (is_head_hands_input(user.roles)) {
    for (const DuetTake& take : library->takes()) {
      Result<HeadHandsBody> body =
          HeadHandsBody::build(take.template_motion.clip, take.template_motion.roles);
      if (!body) return Error{"take " + take.name + ": " + body.error().message};
      head_hands_bodies.push_back(std::move(body).value());
    }
  }
  std::optional<WristsOnUserBody> wrists_on_user_body;
  if (head_hands_bodies.empty()) {
    // A skeleton the retargeter cannot read leaves the contact IK its plain steady difference.
    std::vector<const LoadedMotion*> dancers;
    for (const DuetTake& take : library->takes()) dancers.push_back(&take.template_motion);
    Result<WristsOnUserBody> wrists = WristsOnUserBody::create(std::move(dancers), user);
    if (wrists) wrists_on_user_body = std::move(wrists).value();
  }
  LiveLoop loop(std::move(library), user, std::move(session).value(), std::move(models), params);
  loop.head_hands_bodies_ = std::move(head_hands_bodies);
  loop.wrists_on_user_body_ = std::move(wrists_on_user_body);
  loop.device_correction_ = head_hands_device_correction();
  return loop;
}

std::array<Vec3, 2> LiveLoop::head_hands_wrist_difference_hs(int take,
                                                             double position) const noexcept {
  // The template dancer's body scaled to the user's size, as the body heading assumes.
  std::array<Vec3, 2> difference =
      head_hands_bodies_[static_cast<std::size_t>(take)].wrist_size_difference_hs(
          position, head_hands_size_ratio_);
  // Each hand also sits where the user's shoulders and arms hold it against the template
  // dancers': the offset the follower takes off the hands' places (the body calibration's, told,
  // plus what it has learnt of the rig's posture), in head heights. A wider or higher shoulder
  // moves the hand as much in any pose, so it is taken as a shift; a longer arm looks like a
  // shoulder further forward in the calibration's pose and is taken so too.
  if (head_hands_size_ratio_ > 0.0) {
    const std::array<Vec3, 2> offsets = session_.hand_offsets();
    for (std::size_t s = 0; s < 2; ++s) {
      difference[s] += session_.head_height_m() * offsets[s];
    }
  }
  return difference;
}

void LiveLoop::place_head_hands_user(int take, int frame) noexcept {
  const auto head = static_cast<std::size_t>(user_.roles[Role::kHead]);
  const Vec3& head_position = out_.user_positions_ws[head];
  head_hands_size_ratio_ = 0.0;
  if (!head_position.allFinite()) return;
  const HeadHandsBody& body = head_hands_bodies_[static_cast<std::size_t>(take)];
  const PartnerModel& model = models_[static_cast<std::size_t>(take)];
  // The user's size against the template dancer's, in the follower's own unit: the head's height
  // standing, given by a calibration or learnt as the highest it has been.
  const double size_ratio = body.template_head_height_m() > 0.0
                                ? session_.head_height_m() / body.template_head_height_m()
                                : 1.0;
  const Transform head_frame =
      head_heading_frame(head_position, out_.user_rotations_ws[head] * device_correction_);
  head_hands_size_ratio_ = size_ratio;
  user_pose_.body_heading = body.body_heading(head_frame, frame, size_ratio);
  user_pose_.body_heading_valid = user_pose_.body_heading.translation.allFinite() &&
                                  user_pose_.body_heading.rotation.coeffs().allFinite();
  user_pose_.height_m = model.template_height_m() * size_ratio;
  // The controllers' orientations as the template's wrists would be turned, so the contact IK
  // carries the captured grip offset (IkTarget::kCapturedOffset) in the right frame.
  for (const Side side : {Side::kLeft, Side::kRight}) {
    const auto s = static_cast<std::size_t>(side);
    const auto joint = static_cast<std::size_t>(
        user_.roles[side == Side::kLeft ? Role::kLeftWrist : Role::kRightWrist]);
    user_pose_.wrist_rotations_ws[s] =
        body.template_wrist_rotation(side == Side::kLeft, out_.user_rotations_ws[joint]);
  }
}

LiveLoop::LiveLoop(std::shared_ptr<const DuetLibrary> library, const SourceSkeleton& user,
                   FollowSession session, std::vector<PartnerModel> models,
                   const PartnerParams& params)
    : library_(std::move(library)),
      user_(user),
      session_(std::move(session)),
      models_(std::move(models)),
      params_(params) {
  const auto user_joints = static_cast<std::size_t>(user_.joint_count());
  const int partner_joints = models_[0].response_skeleton().joint_count();
  const auto partner_n = static_cast<std::size_t>(partner_joints);
  context_.resize(partner_joints);
  out_.user_positions_ws.assign(user_joints, Vec3::Zero());
  out_.user_rotations_ws.assign(user_joints, Quat::Identity());
  out_.partner_translations_ls.assign(partner_n, Vec3::Zero());
  out_.partner_rotations_ls.assign(partner_n, Quat::Identity());
  out_.partner_positions_ws.assign(partner_n, Vec3::Zero());
  out_.partner_rotations_ws.assign(partner_n, Quat::Identity());
  shown_pose_.resize(partner_joints);
  user_height_m_ = measure_body(*user_.skeleton, user_.roles).standing_height_m;
  for (const auto& take : library_->takes()) {
    hand_frame_turns_.push_back(hand_frame_turns(*user_.skeleton, user_.roles,
                                                 take.template_motion.clip.skeleton(),
                                                 take.template_motion.roles));
  }
  // Until the first frame, the partner stands in its first captured pose.
  const Clip& response = library_->takes()[0].response_motion.clip;
  std::ranges::copy(response.translations_ls(0), out_.partner_translations_ls.begin());
  std::ranges::copy(response.rotations_ls(0), out_.partner_rotations_ls.begin());
  forward_kinematics(response.skeleton(), out_.partner_translations_ls, out_.partner_rotations_ls,
                     out_.partner_positions_ws, out_.partner_rotations_ws);
}

std::shared_ptr<const Skeleton> LiveLoop::partner_skeleton() const noexcept {
  return models_[0].response_skeleton_ptr();
}

Status LiveLoop::set_head_height(double head_height_m) {
  return session_.set_head_height(head_height_m);
}

Status LiveLoop::set_arms_forward(const std::optional<ArmsForward>& arms_forward) {
  return session_.set_arms_forward(arms_forward);
}

bool LiveLoop::set_correction(std::string_view name, bool enabled) noexcept {
  return duet::set_correction(params_, name, enabled);
}

void LiveLoop::reset() noexcept {
  session_.reset();
  context_.reset();
  playhead_.reset();
  place_.reset();
  unseen_user_.reset();
  has_previous_ = false;
}

const LiveOutput& LiveLoop::step(const SourceFrame& frame) noexcept {
  const FollowResult result =
      session_.step(frame.translations_ls, frame.rotations_ls, frame.time_s);
  ++out_.seq;
  out_.time_s = frame.time_s;
  out_.follow = result;

  forward_kinematics(*user_.skeleton, frame.translations_ls, frame.rotations_ls,
                     out_.user_positions_ws, out_.user_rotations_ws);
  user_pose_ = user_pose_from_world(out_.user_positions_ws, out_.user_rotations_ws, user_.roles);
  user_pose_.height_m = user_height_m_;

  const double dt_s = has_previous_ ? frame.time_s - previous_time_s_ : 0.0;
  const PartnerPlaceStep place = place_.next(result, dt_s, models_, params_.playhead);
  const int take = place.take;
  const int frame_in_take = place.frame;
  const PartnerModel& model = models_[static_cast<std::size_t>(take)];
  const Clip& response = library_->takes()[static_cast<std::size_t>(take)].response_motion.clip;
  if (!head_hands_bodies_.empty()) {
    place_head_hands_user(take, frame_in_take);
  } else {
    const std::array<Quat, 2>& turns = hand_frame_turns_[static_cast<std::size_t>(take)];
    for (std::size_t s = 0; s < 2; ++s) {
      user_pose_.wrist_rotations_ws[s] = (user_pose_.wrist_rotations_ws[s] * turns[s]).normalized();
    }
  }

  PartnerSynthesisJob job;
  job.model = &model;
  job.params = &params_;
  job.jumped = place.jumped;
  job.dt_s = dt_s;
  // The response at the playhead (smooth) or at the estimate itself.
  double position = frame_in_take;
  if (params_.smooth) {
    position = playhead_.advance(frame_in_take + place.frame_offset, job.jumped, result.tempo,
                                 job.dt_s, response.frame_rate(), params_.playhead);
    position = std::clamp(position, 0.0, static_cast<double>(model.frame_count() - 1));
  } else {
    playhead_.reset();
  }
  if (wrists_on_user_body_ && params_.contact) {
    // The bodies' part of the hand's difference feeds only an arm the contact IK holds or lets
    // go: a frame with no contact and no fading arm needs no retargeting (BM_WristsOnUserBody).
    const bool arm_held = model.contacts().mask(static_cast<int>(std::lround(position))) != 0 ||
                          context_.arm_ik_weighted();
    if (arm_held) {
      user_pose_.wrist_body_difference_hs =
          wrists_on_user_body_->wrist_difference_hs(take, position);
    }
  } else if (!head_hands_bodies_.empty() && params_.contact) {
    user_pose_.wrist_body_difference_hs = head_hands_wrist_difference_hs(take, position);
  }
  // The user as last seen, carried on with the dance while the sensor says nothing new, or
  // nothing the follower believes (an outlier frame: a tracker's pop, set aside by the follower);
  // a hand unseen (a controller out of the headset's view reports where it was) is held against
  // the body as seen.
  Transform template_heading = model.alignment().template_heading_at(position);
  template_heading.translation *= model.spacing_scale(user_pose_.height_m);
  const bool body_seen = !result.missing && !result.outlier;
  if (body_seen && result.partly_observed && params_.carry_unseen_user) {
    unseen_user_.hold_hands(user_pose_, {session_.hand_unseen(0), session_.hand_unseen(1)});
  }
  if (body_seen) {
    unseen_user_.seen(user_pose_, template_heading, take);
  } else if (params_.carry_unseen_user) {
    unseen_user_.carry(user_pose_, template_heading, take);
  }
  job.frame = static_cast<int>(std::lround(position));
  job.frame_position = position;
  response.sample(position / response.frame_rate(), shown_pose_);
  job.translations_ls = shown_pose_.translations_ls;
  job.rotations_ls = shown_pose_.rotations_ls;
  job.user = &user_pose_;
  job.context = &context_;
  job.translations_ls_out = out_.partner_translations_ls;
  job.rotations_ls_out = out_.partner_rotations_ls;
  job.info = &out_.partner_info;
  out_.partner_synthesised = job.run();
  if (!out_.partner_synthesised) {
    out_.partner_info = PartnerFrameInfo{};
    std::ranges::copy(job.translations_ls, out_.partner_translations_ls.begin());
    std::ranges::copy(job.rotations_ls, out_.partner_rotations_ls.begin());
  }
  forward_kinematics(model.response_skeleton(), out_.partner_translations_ls,
                     out_.partner_rotations_ls, out_.partner_positions_ws,
                     out_.partner_rotations_ws);

  const std::uint8_t mask = model.contacts().mask(frame_in_take);
  out_.contact_left = out_.contact_right = false;
  for (int pair = 0; pair < kHandPairCount; ++pair) {
    if ((mask & (1u << pair)) == 0) continue;
    (template_side(pair) == Side::kLeft ? out_.contact_left : out_.contact_right) = true;
  }
  out_.partner_take = take;
  out_.partner_frame = job.frame;

  if (std::isfinite(frame.time_s)) {
    previous_time_s_ = frame.time_s;
    has_previous_ = true;
  }
  return out_;
}

}  // namespace duet
