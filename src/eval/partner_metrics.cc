#include "duet/eval/partner_metrics.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"

namespace duet {

namespace {

constexpr std::array<Role, 2> kWrists = {Role::kLeftWrist, Role::kRightWrist};
constexpr std::array<Role, 2> kToes = {Role::kLeftToe, Role::kRightToe};

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::ranges::sort(values);
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

bool valid_dt(double dt_s) { return dt_s > 0.0 && std::isfinite(dt_s); }

}  // namespace

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::ranges::sort(values);
  const double rank = std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size()));
  const auto k = static_cast<std::size_t>(std::max(rank, 1.0)) - 1;
  return values[std::min(k, values.size() - 1)];
}

double mean_joint_distance_m(std::span<const Vec3> a, std::span<const Vec3> b) {
  assert(a.size() == b.size() && !a.empty());
  const std::size_t n = std::min(a.size(), b.size());
  if (n == 0) return 0.0;
  double sum = 0.0;
  for (std::size_t j = 0; j < n; ++j) sum += (a[j] - b[j]).norm();
  return sum / static_cast<double>(n);
}

double angular_speed_rad_s(const Quat& previous, const Quat& current, double dt_s) {
  if (!valid_dt(dt_s)) return 0.0;
  // |dot| of unit quaternions is cos(angle / 2); the abs takes the shorter way round.
  const double dot = std::abs(previous.normalized().dot(current.normalized()));
  return 2.0 * std::acos(std::min(dot, 1.0)) / dt_s;
}

double max_joint_angular_speed_rad_s(const Skeleton& skeleton, std::span<const Quat> previous_ls,
                                     std::span<const Quat> current_ls, double dt_s) {
  double largest = 0.0;
  const std::size_t n = std::min({previous_ls.size(), current_ls.size(), skeleton.joints.size()});
  for (std::size_t j = 0; j < n; ++j) {
    if (skeleton.joints[j].end_site) continue;
    largest = std::max(largest, angular_speed_rad_s(previous_ls[j], current_ls[j], dt_s));
  }
  return largest;
}

bool foot_near_ground(const Vec3& previous_ws, const Vec3& current_ws, double ground_height_m,
                      const FootSlipThresholds& thresholds) {
  const double margin = thresholds.height_margin_m;
  return previous_ws.y() - ground_height_m <= margin && current_ws.y() - ground_height_m <= margin;
}

double horizontal_speed_mps(const Vec3& previous_ws, const Vec3& current_ws, double dt_s) {
  if (!valid_dt(dt_s)) return 0.0;
  const double dx = current_ws.x() - previous_ws.x(), dz = current_ws.z() - previous_ws.z();
  return std::sqrt(dx * dx + dz * dz) / dt_s;
}

bool foot_slips(const Vec3& previous_ws, const Vec3& current_ws, double ground_height_m,
                double dt_s, const FootSlipThresholds& thresholds) {
  return valid_dt(dt_s) && foot_near_ground(previous_ws, current_ws, ground_height_m, thresholds) &&
         horizontal_speed_mps(previous_ws, current_ws, dt_s) > thresholds.speed_mps;
}

// ---------------------------------------------------------------------------------------------
// JerkMeter

JerkMeter::JerkMeter(std::size_t joints)
    : position_(joints, Vec3::Zero()),
      velocity_(joints, Vec3::Zero()),
      acceleration_(joints, Vec3::Zero()) {}

double JerkMeter::add(std::span<const Vec3> positions_ws, double dt_s) noexcept {
  const std::size_t n = std::min(positions_ws.size(), position_.size());
  if (known_ > 0 && !valid_dt(dt_s)) known_ = 0;
  double sum = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const Vec3& p = positions_ws[j];
    if (known_ >= 1) {
      const Vec3 v = (p - position_[j]) / dt_s;
      if (known_ >= 2) {
        const Vec3 a = (v - velocity_[j]) / dt_s;
        if (known_ >= 3) sum += ((a - acceleration_[j]) / dt_s).norm();
        acceleration_[j] = a;
      }
      velocity_[j] = v;
    }
    position_[j] = p;
  }
  const bool has_jerk = known_ >= 3 && n > 0;
  known_ = std::min(known_ + 1, 4);
  return has_jerk ? sum / static_cast<double>(n) : -1.0;
}

// ---------------------------------------------------------------------------------------------
// CapturedDuetSampler

CapturedDuetSampler::CapturedDuetSampler(const Clip& template_clip,
                                         const JointRoles& template_roles,
                                         const Clip& response_clip, const PartnerModel& model)
    : template_clip_(&template_clip),
      template_roles_(template_roles),
      response_clip_(&response_clip),
      model_(&model) {
  template_pose_.resize(template_clip.joint_count());
  response_pose_.resize(response_clip.joint_count());
  placed_pose_.resize(response_clip.joint_count());
  template_positions_.assign(static_cast<std::size_t>(template_clip.joint_count()), Vec3::Zero());
  response_positions_.assign(static_cast<std::size_t>(response_clip.joint_count()), Vec3::Zero());
  placed_positions_.assign(static_cast<std::size_t>(response_clip.joint_count()), Vec3::Zero());
  rotations_scratch_.assign(
      static_cast<std::size_t>(std::max(template_clip.joint_count(), response_clip.joint_count())),
      Quat::Identity());
}

void CapturedDuetSampler::compute(double template_frame, const Vec3& user_root_position_ws,
                                  const Quat& user_root_rotation_ws) {
  compute(template_frame, heading_frame(user_root_position_ws, user_root_rotation_ws));
}

void CapturedDuetSampler::compute(double template_frame, const Transform& user_heading,
                                  double spacing_scale) {
  const int last = response_clip_->frame_count() - 1;
  const double frame = std::clamp(template_frame, 0.0, static_cast<double>(last));
  const double time_s = frame / response_clip_->frame_rate();
  template_clip_->sample(time_s, template_pose_);
  response_clip_->sample(time_s, response_pose_);
  const auto tn = static_cast<std::size_t>(template_clip_->joint_count());
  const auto rn = static_cast<std::size_t>(response_clip_->joint_count());
  forward_kinematics(template_clip_->skeleton(), template_pose_.translations_ls,
                     template_pose_.rotations_ls, template_positions_,
                     std::span(rotations_scratch_).first(tn));
  forward_kinematics(response_clip_->skeleton(), response_pose_.translations_ls,
                     response_pose_.rotations_ls, response_positions_,
                     std::span(rotations_scratch_).first(rn));

  const RootPlacement placement = model_->alignment().placement_at(frame);
  Transform root =
      user_heading * Transform{placement.rotation_hs, placement.spaced_position_hs(spacing_scale)};
  root.rotation.normalize();
  placed_pose_.translations_ls = response_pose_.translations_ls;
  placed_pose_.rotations_ls = response_pose_.rotations_ls;
  placed_pose_.translations_ls[0] = root.translation;
  placed_pose_.rotations_ls[0] = root.rotation;
  forward_kinematics(response_clip_->skeleton(), placed_pose_.translations_ls,
                     placed_pose_.rotations_ls, placed_positions_,
                     std::span(rotations_scratch_).first(rn));

  mask_ = model_->contacts().mask(static_cast<int>(std::lround(frame)));
}

double CapturedDuetSampler::captured_wrist_distance_m(int pair) const {
  const int t = template_roles_[kWrists[static_cast<std::size_t>(template_side(pair))]];
  const int r = model_->response_roles()[kWrists[static_cast<std::size_t>(response_side(pair))]];
  return (template_positions_[static_cast<std::size_t>(t)] -
          response_positions_[static_cast<std::size_t>(r)])
      .norm();
}

// ---------------------------------------------------------------------------------------------
// Captured reference

void add_captured_reference(const Clip& response, const JointRoles& roles,
                            const std::array<double, 2>& ground_heights,
                            const PartnerMetricsOptions& options, CapturedReference& reference) {
  const int frames = response.frame_count();
  if (frames < 2) return;
  const double dt = response.frame_time();
  const std::vector<Vec3> positions = world_positions(response);
  const auto joints = static_cast<std::size_t>(response.joint_count());
  const Skeleton& skeleton = response.skeleton();
  std::vector<double> frame_max(static_cast<std::size_t>(frames), 0.0);
  for (int f = 1; f < frames; ++f) {
    const auto fs = static_cast<std::size_t>(f);
    bool slip = false;
    for (std::size_t side = 0; side < 2; ++side) {
      const auto toe = static_cast<std::size_t>(roles[kToes[side]]);
      const Vec3& a = positions[(fs - 1) * joints + toe];
      const Vec3& b = positions[fs * joints + toe];
      slip = slip || foot_slips(a, b, ground_heights[side], dt, options.slip);
      if (foot_near_ground(a, b, ground_heights[side], options.slip)) {
        reference.ground_speed_sum_mps += horizontal_speed_mps(a, b, dt);
        ++reference.ground_feet;
      }
    }
    reference.slip_frames += slip ? 1 : 0;
    ++reference.frames;
    const std::span<const Quat> previous = response.rotations_ls(f - 1);
    const std::span<const Quat> current = response.rotations_ls(f);
    for (std::size_t j = 0; j < joints; ++j) {
      if (skeleton.joints[j].end_site) continue;
      const double speed = angular_speed_rad_s(previous[j], current[j], dt);
      reference.angular_speeds_rad_s.push_back(speed);
      frame_max[fs] = std::max(frame_max[fs], speed);
    }
    reference.frame_max_rad_s.push_back(frame_max[fs]);
  }
  // Non-overlapping windows of the post-jump length, from the second frame on.
  const int window = std::max(1, static_cast<int>(std::lround(options.post_jump_window_s / dt)));
  for (int begin = 1; begin + window <= frames; begin += window) {
    reference.window_max_rad_s.push_back(
        *std::max_element(frame_max.begin() + begin, frame_max.begin() + begin + window));
    ++reference.windows;
  }
}

// ---------------------------------------------------------------------------------------------
// Accumulator

void PartnerMetricsAccumulator::add(const Performance& performance,
                                    std::span<const PartnerFrameRecord> records) {
  assert(records.size() == performance.truth.size());
  const std::size_t n = std::min(records.size(), performance.truth.size());
  // Frames where the captured partner keeps clear of the user, and the partner does not. A true
  // jump's own frame is left out: the true response is cut there, the partner cannot be.
  const auto uncrowded_truth = [&](std::size_t f) {
    return !performance.truth[f].jump &&
           records[f].true_user_distance_m >= options_.crowd_distance_m + options_.crowd_margin_m;
  };
  const auto crowded = [&](std::size_t f) {
    return records[f].user_distance_m < options_.crowd_distance_m && uncrowded_truth(f);
  };
  for (std::size_t f = 0; f < n; ++f) {
    const PartnerFrameRecord& r = records[f];
    ++frames_;
    if (uncrowded_truth(f)) closest_m_ = std::min(closest_m_, r.user_distance_m);
    crowded_frames_ += crowded(f) ? 1 : 0;
    joint_error_sum_m_ += r.joint_error_m;
    step_us_sum_ += r.step_us;
    for (int pair = 0; pair < kHandPairCount; ++pair) {
      if ((r.hand_pairs & (1u << pair)) != 0) {
        hand_errors_m_.push_back(r.hand_error_m[static_cast<std::size_t>(pair)]);
        sensed_hand_errors_m_.push_back(r.sensed_hand_error_m[static_cast<std::size_t>(pair)]);
      }
    }
    if (r.jerk_mps3 >= 0.0) {
      jerk_sum_ += r.jerk_mps3;
      ++jerk_frames_;
    }
    if (r.true_jerk_mps3 >= 0.0) {
      true_jerk_sum_ += r.true_jerk_mps3;
      ++true_jerk_frames_;
    }
    if (f > 0) {
      ++slip_pairs_;
      slip_frames_ += r.slip ? 1 : 0;
      ground_speed_sum_mps_ += r.ground_speed_sum_mps;
      ground_feet_ += r.ground_feet;
      frame_max_rad_s_.push_back(r.max_angular_speed_rad_s);
      if (!performance.truth[f].jump)
        true_frame_max_rad_s_.push_back(r.true_max_angular_speed_rad_s);
      max_slide_mps_ = std::max(max_slide_mps_, r.planted_slide_mps);
      sliding_frames_ += r.planted_slide_mps > options_.slide_limit_mps ? 1 : 0;
    }
  }
  // Rejoined at frame f: hands and spacing within the tolerance from f for rejoin_hold_s (or to
  // the end of the performance).
  const auto rejoined_from = [&](std::size_t f) {
    for (std::size_t g = f;
         g < n && performance.times_s[g] < performance.times_s[f] + options_.rejoin_hold_s; ++g) {
      if (!records[g].hands_joined || records[g].spacing_error_m > options_.rejoin_tolerance_m) {
        return false;
      }
    }
    return true;
  };
  // Jump windows: frames from the jump frame to window seconds after it; frame 0 has no speed.
  for (std::size_t j = 0; j < n; ++j) {
    if (!performance.truth[j].jump) continue;
    const double end = performance.times_s[j] + options_.post_jump_window_s;
    double largest = -1.0, true_largest = 0.0;
    for (std::size_t f = std::max<std::size_t>(j, 1); f < n && performance.times_s[f] < end; ++f) {
      largest = std::max(largest, records[f].max_angular_speed_rad_s);
      true_largest = std::max(true_largest, records[f].true_max_angular_speed_rad_s);
    }
    if (largest < 0.0) continue;
    jump_max_rad_s_.push_back(largest);
    jump_true_max_rad_s_.push_back(true_largest);

    const double t0 = performance.times_s[j];
    double rejoin = std::numeric_limits<double>::infinity();
    double spacing = -1.0, slide = 0.0;
    bool crowd = false;
    for (std::size_t f = j; f < n && performance.times_s[f] < t0 + options_.rejoin_search_s; ++f) {
      const double t = performance.times_s[f] - t0;
      if (!std::isfinite(rejoin) && rejoined_from(f)) rejoin = t;
      if (spacing < 0.0 && t >= options_.rejoin_deadline_s - 1e-9) {
        spacing = records[f].spacing_error_m;
      }
      if (f > j && t < options_.post_jump_window_s) {
        slide = std::max(slide, records[f].planted_slide_mps);
      }
      if (t < options_.post_jump_window_s) crowd = crowd || crowded(f);
    }
    jump_rejoin_s_.push_back(rejoin);
    // A performance that ends first: the last frame's spacing.
    jump_spacing_m_.push_back(spacing >= 0.0 ? spacing : records[n - 1].spacing_error_m);
    jump_slide_mps_.push_back(slide);
    jumps_crowded_ += crowd ? 1 : 0;
  }
}

void PartnerMetricsAccumulator::add_reference(const CapturedReference& reference) {
  reference_.slip_frames += reference.slip_frames;
  reference_.frames += reference.frames;
  reference_.ground_speed_sum_mps += reference.ground_speed_sum_mps;
  reference_.ground_feet += reference.ground_feet;
  reference_.windows += reference.windows;
  reference_.angular_speeds_rad_s.insert(reference_.angular_speeds_rad_s.end(),
                                         reference.angular_speeds_rad_s.begin(),
                                         reference.angular_speeds_rad_s.end());
  reference_.window_max_rad_s.insert(reference_.window_max_rad_s.end(),
                                     reference.window_max_rad_s.begin(),
                                     reference.window_max_rad_s.end());
  reference_.frame_max_rad_s.insert(reference_.frame_max_rad_s.end(),
                                    reference.frame_max_rad_s.begin(),
                                    reference.frame_max_rad_s.end());
}

void PartnerMetricsAccumulator::merge(const PartnerMetricsAccumulator& other) {
  frames_ += other.frames_;
  slip_frames_ += other.slip_frames_;
  slip_pairs_ += other.slip_pairs_;
  ground_feet_ += other.ground_feet_;
  ground_speed_sum_mps_ += other.ground_speed_sum_mps_;
  joint_error_sum_m_ += other.joint_error_sum_m_;
  step_us_sum_ += other.step_us_sum_;
  jerk_sum_ += other.jerk_sum_;
  jerk_frames_ += other.jerk_frames_;
  true_jerk_sum_ += other.true_jerk_sum_;
  true_jerk_frames_ += other.true_jerk_frames_;
  hand_errors_m_.insert(hand_errors_m_.end(), other.hand_errors_m_.begin(),
                        other.hand_errors_m_.end());
  sensed_hand_errors_m_.insert(sensed_hand_errors_m_.end(), other.sensed_hand_errors_m_.begin(),
                               other.sensed_hand_errors_m_.end());
  jump_max_rad_s_.insert(jump_max_rad_s_.end(), other.jump_max_rad_s_.begin(),
                         other.jump_max_rad_s_.end());
  jump_true_max_rad_s_.insert(jump_true_max_rad_s_.end(), other.jump_true_max_rad_s_.begin(),
                              other.jump_true_max_rad_s_.end());
  frame_max_rad_s_.insert(frame_max_rad_s_.end(), other.frame_max_rad_s_.begin(),
                          other.frame_max_rad_s_.end());
  true_frame_max_rad_s_.insert(true_frame_max_rad_s_.end(), other.true_frame_max_rad_s_.begin(),
                               other.true_frame_max_rad_s_.end());
  jump_rejoin_s_.insert(jump_rejoin_s_.end(), other.jump_rejoin_s_.begin(),
                        other.jump_rejoin_s_.end());
  jump_spacing_m_.insert(jump_spacing_m_.end(), other.jump_spacing_m_.begin(),
                         other.jump_spacing_m_.end());
  jump_slide_mps_.insert(jump_slide_mps_.end(), other.jump_slide_mps_.begin(),
                         other.jump_slide_mps_.end());
  max_slide_mps_ = std::max(max_slide_mps_, other.max_slide_mps_);
  sliding_frames_ += other.sliding_frames_;
  crowded_frames_ += other.crowded_frames_;
  jumps_crowded_ += other.jumps_crowded_;
  closest_m_ = std::min(closest_m_, other.closest_m_);
  add_reference(other.reference_);
}

PartnerMetrics PartnerMetricsAccumulator::summary() const {
  PartnerMetrics m;
  m.frames = frames_;
  if (frames_ > 0) {
    m.mean_joint_error_cm = 100.0 * joint_error_sum_m_ / static_cast<double>(frames_);
    m.mean_step_us = step_us_sum_ / static_cast<double>(frames_);
  }
  if (jerk_frames_ > 0) m.mean_jerk_mps3 = jerk_sum_ / static_cast<double>(jerk_frames_);
  if (true_jerk_frames_ > 0) {
    m.true_mean_jerk_mps3 = true_jerk_sum_ / static_cast<double>(true_jerk_frames_);
  }
  m.hand_samples = static_cast<long long>(hand_errors_m_.size());
  if (!hand_errors_m_.empty()) {
    m.median_hand_error_cm = 100.0 * median(hand_errors_m_);
    m.median_sensed_hand_error_cm = 100.0 * median(sensed_hand_errors_m_);
    double sum = 0.0;
    for (const double e : hand_errors_m_) sum += e;
    m.mean_hand_error_cm = 100.0 * sum / static_cast<double>(hand_errors_m_.size());
  }
  if (slip_pairs_ > 0) {
    m.slip_rate = static_cast<double>(slip_frames_) / static_cast<double>(slip_pairs_);
  }
  if (ground_feet_ > 0) {
    m.ground_speed_cm_s = 100.0 * ground_speed_sum_mps_ / static_cast<double>(ground_feet_);
  }
  if (reference_.ground_feet > 0) {
    m.captured_ground_speed_cm_s =
        100.0 * reference_.ground_speed_sum_mps / static_cast<double>(reference_.ground_feet);
  }
  if (reference_.frames > 0) {
    m.captured_slip_rate =
        static_cast<double>(reference_.slip_frames) / static_cast<double>(reference_.frames);
  }
  const double reference_rad_s =
      quantile(reference_.angular_speeds_rad_s, options_.reference_percentile);
  m.reference_speed_deg_s = rad_to_deg(reference_rad_s);
  if (!reference_.window_max_rad_s.empty()) {
    const auto over = std::ranges::count_if(reference_.window_max_rad_s,
                                            [&](double s) { return s > reference_rad_s; });
    m.captured_windows_over_reference =
        static_cast<double>(over) / static_cast<double>(reference_.window_max_rad_s.size());
  }
  const double window_reference_rad_s =
      reference_.window_max_rad_s.empty()
          ? reference_rad_s
          : quantile(reference_.window_max_rad_s, options_.reference_percentile);
  m.window_reference_speed_deg_s = rad_to_deg(window_reference_rad_s);
  m.jumps = static_cast<long long>(jump_max_rad_s_.size());
  if (!jump_max_rad_s_.empty()) {
    m.max_jump_speed_deg_s = rad_to_deg(*std::ranges::max_element(jump_max_rad_s_));
    m.median_jump_speed_deg_s = rad_to_deg(median(jump_max_rad_s_));
    m.jumps_over_reference =
        std::ranges::count_if(jump_max_rad_s_, [&](double s) { return s > reference_rad_s; });
    m.jumps_over_window_reference = std::ranges::count_if(
        jump_max_rad_s_, [&](double s) { return s > window_reference_rad_s; });
    for (std::size_t k = 0; k < jump_max_rad_s_.size(); ++k) {
      m.jumps_over_truth +=
          jump_max_rad_s_[k] > std::max(reference_rad_s, jump_true_max_rad_s_[k]) ? 1 : 0;
      m.jumps_over_window_reference_and_truth +=
          jump_max_rad_s_[k] > std::max(window_reference_rad_s, jump_true_max_rad_s_[k]) ? 1 : 0;
    }
    m.median_true_jump_speed_deg_s = rad_to_deg(median(jump_true_max_rad_s_));
    m.median_rejoin_s = median(jump_rejoin_s_);
    m.max_rejoin_s = *std::ranges::max_element(jump_rejoin_s_);
    m.jumps_rejoined_in_time = std::ranges::count_if(
        jump_rejoin_s_, [&](double s) { return s <= options_.rejoin_deadline_s + 1e-9; });
    m.median_spacing_error_cm = 100.0 * median(jump_spacing_m_);
    m.max_spacing_error_cm = 100.0 * *std::ranges::max_element(jump_spacing_m_);
    m.max_jump_slide_mps = *std::ranges::max_element(jump_slide_mps_);
    m.jumps_sliding = std::ranges::count_if(jump_slide_mps_,
                                            [&](double s) { return s > options_.slide_limit_mps; });
  }
  m.frame_speed_deg_s = rad_to_deg(quantile(frame_max_rad_s_, options_.reference_percentile));
  m.captured_frame_speed_deg_s =
      rad_to_deg(quantile(reference_.frame_max_rad_s, options_.reference_percentile));
  if (!true_frame_max_rad_s_.empty()) {
    m.true_frame_speed_deg_s =
        rad_to_deg(quantile(true_frame_max_rad_s_, options_.reference_percentile));
  }
  m.max_slide_mps = max_slide_mps_;
  m.sliding_frames = sliding_frames_;
  m.crowded_frames = crowded_frames_;
  m.jumps_crowded = jumps_crowded_;
  m.closest_cm = std::isfinite(closest_m_) ? 100.0 * closest_m_ : -1.0;
  return m;
}

}  // namespace duet
