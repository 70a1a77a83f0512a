#include "duet/partner/partner_synthesis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "duet/math/rotation.h"
#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/partner/ik_two_bone_job.h"

namespace duet {
namespace {

// A two-bone chain of the pose (shoulder, elbow, wrist or hip, knee, ankle): its joints and their
// world frames, as IkTwoBoneJob takes them.
struct TwoBoneChain {
  std::size_t start, mid, end;
  Transform start_ws, mid_ws, end_ws;
};

TwoBoneChain chain_of(const JointRoles& roles, Role start, Role mid, Role end,
                      std::span<const Vec3> positions_ws, std::span<const Quat> rotations_ws) {
  const auto s = static_cast<std::size_t>(roles[start]);
  const auto m = static_cast<std::size_t>(roles[mid]);
  const auto e = static_cast<std::size_t>(roles[end]);
  return {s,
          m,
          e,
          {rotations_ws[s], positions_ws[s]},
          {rotations_ws[m], positions_ws[m]},
          {rotations_ws[e], positions_ws[e]}};
}

// The IK job for `chain` from these local rotations of its first two joints towards target_ws;
// the caller sets the weight and the outputs. The chain and rotations must outlive the job.
IkTwoBoneJob chain_job(const TwoBoneChain& chain, const Quat& start_ls, const Quat& mid_ls,
                       const Vec3& target_ws) {
  IkTwoBoneJob ik;
  ik.start_joint_ws = &chain.start_ws;
  ik.mid_joint_ws = &chain.mid_ws;
  ik.end_joint_ws = &chain.end_ws;
  ik.start_rotation_ls = &start_ls;
  ik.mid_rotation_ls = &mid_ls;
  ik.target_ws = target_ws;
  return ik;
}

struct ArmRoles {
  Role shoulder, elbow, wrist;
};
constexpr std::array<ArmRoles, 2> kArms = {
    {{Role::kLeftShoulder, Role::kLeftElbow, Role::kLeftWrist},
     {Role::kRightShoulder, Role::kRightElbow, Role::kRightWrist}}};
constexpr std::array<Role, 2> kToes = {Role::kLeftToe, Role::kRightToe};
struct LegRoles {
  Role hip, knee, ankle, toe;
};
constexpr std::array<LegRoles, 2> kLegs = {
    {{Role::kLeftHip, Role::kLeftKnee, Role::kLeftAnkle, Role::kLeftToe},
     {Role::kRightHip, Role::kRightKnee, Role::kRightAnkle, Role::kRightToe}}};
// A blend with offsets below these is over (the foot hold starts no new holds).
constexpr double kBlendingRad = 0.02, kBlendingM = 0.01;

bool is_ancestor(const Skeleton& skeleton, int ancestor, int joint) {
  for (int j = joint; j >= 0; j = skeleton.joints[static_cast<std::size_t>(j)].parent) {
    if (j == ancestor) return true;
  }
  return false;
}

bool valid_joint(const Skeleton& skeleton, int j) { return j >= 0 && j < skeleton.joint_count(); }

std::string role_joint(const Skeleton& skeleton, const JointRoles& roles, Role role) {
  const int j = roles[role];
  return std::string(role_name(role)) + " ('" +
         (valid_joint(skeleton, j) ? skeleton.joints[static_cast<std::size_t>(j)].name
                                   : std::string("none")) +
         "')";
}

Status check_response_roles(const Skeleton& skeleton, const JointRoles& roles) {
  for (const ArmRoles& arm : kArms) {
    for (const Role role : {arm.shoulder, arm.elbow, arm.wrist}) {
      if (!valid_joint(skeleton, roles[role])) {
        return Error{"partner model: the response skeleton has no " + std::string(role_name(role)) +
                     " joint"};
      }
    }
    if (!is_ancestor(skeleton, roles[arm.shoulder], roles[arm.elbow]) ||
        !is_ancestor(skeleton, roles[arm.elbow], roles[arm.wrist]) ||
        roles[arm.shoulder] == roles[arm.elbow] || roles[arm.elbow] == roles[arm.wrist]) {
      return Error{"partner model: the response arm " + role_joint(skeleton, roles, arm.shoulder) +
                   " -> " + role_joint(skeleton, roles, arm.elbow) + " -> " +
                   role_joint(skeleton, roles, arm.wrist) +
                   " is not a chain (each joint must lie below the previous one)"};
    }
  }
  // IK on one arm must not move the other (both are solved from one forward kinematics pass).
  for (int side = 0; side < 2; ++side) {
    const ArmRoles& arm = kArms[static_cast<std::size_t>(side)];
    const ArmRoles& other = kArms[static_cast<std::size_t>(1 - side)];
    for (const Role role : {other.shoulder, other.elbow, other.wrist}) {
      if (is_ancestor(skeleton, roles[arm.shoulder], roles[role])) {
        return Error{"partner model: the response's " + role_joint(skeleton, roles, role) +
                     " lies below " + role_joint(skeleton, roles, arm.shoulder) +
                     "; the two arms must be separate chains"};
      }
    }
  }
  for (const Role toe : kToes) {
    if (!valid_joint(skeleton, roles[toe])) {
      return Error{"partner model: the response skeleton has no " + std::string(role_name(toe)) +
                   " joint"};
    }
  }
  return Ok{};
}

// Each leg a chain thigh -> knee -> ankle -> toe, the two legs separate (the foot hold's IK
// solves both from one forward kinematics pass).
bool legs_are_chains(const Skeleton& skeleton, const JointRoles& roles) {
  for (std::size_t side = 0; side < 2; ++side) {
    const LegRoles& leg = kLegs[side];
    const int hip = roles[leg.hip], knee = roles[leg.knee], ankle = roles[leg.ankle];
    const int toe = roles[leg.toe];
    for (const int j : {hip, knee, ankle, toe}) {
      if (!valid_joint(skeleton, j)) return false;
    }
    if (hip == knee || knee == ankle || !is_ancestor(skeleton, hip, knee) ||
        !is_ancestor(skeleton, knee, ankle) || !is_ancestor(skeleton, ankle, toe)) {
      return false;
    }
    const LegRoles& other = kLegs[1 - side];
    for (const Role role : {other.hip, other.knee, other.ankle}) {
      if (is_ancestor(skeleton, hip, roles[role])) return false;
    }
  }
  return true;
}

bool finite_time(double t) { return t >= 0.0 && std::isfinite(t); }

double smoothstep(double x) { return x * x * (3.0 - 2.0 * x); }

// `to`, or the point `most` from `from` towards it when it is further: a step under a speed limit.
Vec3 step_towards(const Vec3& from, const Vec3& to, double most) {
  const double distance = (to - from).norm();
  return distance > most ? Vec3(from + (to - from) * (most / distance)) : to;
}

// One frame of an arm joint's IK correction (a rotation vector): `raw`'s part beyond `base`
// through the joint's 1-euro filter, `base` as it is, then at most `most` from what was shown last
// frame once the filter has a past. Returns the new `shown`.
Vec3 step_correction(OneEuroFilter3& filter, Vec3& shown, const Vec3& raw, const Vec3& base,
                     double dt, const OneEuroParams& params, double most) {
  const bool primed = filter.primed();
  const Vec3 filtered = base + filter.filter(raw - base, dt, params);
  shown = primed ? step_towards(shown, filtered, most) : filtered;
  return shown;
}

// A blended place passes the user no nearer than this (pelvis centres, metres) unless an end does.
constexpr double kKeepOutM = 0.4;
// The detour is fullest where the line passes nearest, but within this part of the blend, so that
// it never swings out within a few frames of either end.
constexpr double kDetourPeakRange[2] = {0.2, 0.8};

// Where on the segment a-b (horizontal: x and z) the point nearest the origin lies: 0 at a, 1 at b.
double nearest_along_segment_2d(const Vec3& a, const Vec3& b) {
  const double dx = b.x() - a.x(), dz = b.z() - a.z();
  const double length2 = dx * dx + dz * dz;
  return length2 > 0.0 ? std::clamp(-(a.x() * dx + a.z() * dz) / length2, 0.0, 1.0) : 0.0;
}

// The detour's share at a blend's progress p (0 at the start, 1 at the end): 1 at `peak`, where
// the straight line passes nearest the user, 0 at both ends, a quarter sine on either side.
double detour_share(double p, double peak) {
  constexpr double kQuarter = std::numbers::pi / 2.0;
  return p <= peak ? std::sin(kQuarter * p / peak) : std::sin(kQuarter * (1.0 - p) / (1.0 - peak));
}

// The half-life at which a critically damped offset of size x0 (decaying from rest) peaks at
// max_speed: the peak speed is x0 * y / e with y = 2 ln 2 / half-life. At least `minimum`.
double capped_half_life(double minimum, double x0, double max_speed) {
  constexpr double kPeak = 2.0 * 0.69314718055994531 / 2.71828182845904524;
  if (!(max_speed > 0.0) || !std::isfinite(x0)) return minimum;
  return std::max(minimum, kPeak * x0 / max_speed);
}

// Where the end (wrist) of an arm lands when the local rotations of its start (shoulder) and
// mid (elbow) joints change from `*_before` to `*_after`; start/mid/end: world transforms before.
// Joints between them keep their local rotations, so each segment turns with its upper joint.
Vec3 arm_end_position(const Transform& start, const Transform& mid, const Transform& end,
                      const Quat& start_before, const Quat& mid_before, const Quat& start_after,
                      const Quat& mid_after) {
  // World rotation of the start after: its parent's (unchanged) times the new local rotation.
  const Quat start_turn = start.rotation * start_before.conjugate() * start_after *
                          start.rotation.conjugate();  // world-frame turn about the start
  const Vec3 mid_position = start.translation + start_turn * (mid.translation - start.translation);
  const Quat mid_rotation = start_turn * mid.rotation;  // the mid as moved with its parent chain
  const Quat mid_turn =
      mid_rotation * mid_before.conjugate() * mid_after * mid_rotation.conjugate();
  return mid_position + mid_turn * (start_turn * (end.translation - mid.translation));
}

bool finite_pose(const UserPose& user, Side side) {
  const auto s = static_cast<std::size_t>(side);
  return user.wrist_positions_ws[s].allFinite() && user.wrist_rotations_ws[s].coeffs().allFinite();
}

// The RMS over the axes of a vector's jitter, per-axis meters.
double jitter_rms(const std::array<JitterMeter, 3>& meters) {
  double variance = 0.0;
  for (const JitterMeter& meter : meters) variance += meter.rms() * meter.rms();
  return std::sqrt(variance);
}

// Adds one sample of a vector to its per-axis meters (time constant 1 s; a second difference
// over max_step is a move, not jitter) and returns its jitter's RMS over the axes.
double add_vector_jitter(std::array<JitterMeter, 3>& meters, const Vec3& value, double dt,
                         double max_step, bool restart) {
  constexpr double kJitterTimeConstantS = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    JitterMeter& meter = meters[static_cast<std::size_t>(axis)];
    if (restart) meter.restart();
    meter.add(value[axis], dt, kJitterTimeConstantS, max_step);
  }
  return jitter_rms(meters);
}

SteadyDifferenceParams steady_difference_params(const PartnerParams& p) {
  return {p.ik_difference_time_constant_s, p.ik_difference_power_time_constant_s};
}

// The q-quantile over the clip's frames of the largest angular speed of any joint's local
// rotation since the frame before (End Sites left out), rad/s at the clip's rate: how fast the
// captured dancer's fastest joint turns, bar its rarest moments.
double largest_joint_speed_quantile(const Clip& clip, double q) {
  const int frames = clip.frame_count();
  if (frames < 2) return 0.0;
  const Skeleton& skeleton = clip.skeleton();
  std::vector<double> largest(static_cast<std::size_t>(frames - 1), 0.0);
  for (int f = 1; f < frames; ++f) {
    const std::span<const Quat> before = clip.rotations_ls(f - 1);
    const std::span<const Quat> now = clip.rotations_ls(f);
    double& most = largest[static_cast<std::size_t>(f - 1)];
    for (std::size_t j = 0; j < now.size(); ++j) {
      if (skeleton.joints[j].end_site) continue;
      most = std::max(most, before[j].angularDistance(now[j]));
    }
  }
  const auto k = static_cast<std::size_t>(std::floor(q * static_cast<double>(largest.size() - 1)));
  std::nth_element(largest.begin(), largest.begin() + static_cast<std::ptrdiff_t>(k),
                   largest.end());
  return largest[k] * clip.frame_rate();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// PartnerModel

Result<PartnerModel> PartnerModel::build(const Clip& template_clip,
                                         const JointRoles& template_roles,
                                         const Clip& response_clip,
                                         const JointRoles& response_roles,
                                         const PartnerModelOptions& options) {
  if (response_clip.joint_count() == 0) return Error{"partner model: the response clip is empty"};
  if (Status s = check_response_roles(response_clip.skeleton(), response_roles); !s) {
    return s.error();
  }
  if (!(options.ground_quantile >= 0.0 && options.ground_quantile <= 1.0)) {
    return Error{"partner model: ground_quantile must be in [0, 1]"};
  }
  Result<SpatialAlignment> alignment =
      SpatialAlignment::build(template_clip, template_roles, response_clip);
  if (!alignment) return alignment.error();
  Result<HandContacts> contacts = HandContacts::detect(template_clip, template_roles, response_clip,
                                                       response_roles, options.contacts);
  if (!contacts) return contacts.error();

  PartnerModel model;
  model.response_skeleton_ = response_clip.skeleton_ptr();
  model.response_roles_ = response_roles;
  model.alignment_ = std::move(alignment).value();
  model.contacts_ = std::move(contacts).value();
  model.template_height_m_ =
      measure_body(template_clip.skeleton(), template_roles).standing_height_m;
  model.response_height_m_ =
      measure_body(response_clip.skeleton(), response_roles).standing_height_m;
  model.has_legs_ = legs_are_chains(response_clip.skeleton(), response_roles);

  // Ground height per foot: a low quantile of the toe's height over the clip.
  const std::vector<Vec3> positions = world_positions(response_clip);
  const auto joints = static_cast<std::size_t>(response_clip.joint_count());
  for (std::size_t side = 0; side < 2; ++side) {
    const auto toe = static_cast<std::size_t>(response_roles[kToes[side]]);
    std::vector<double> heights(static_cast<std::size_t>(response_clip.frame_count()));
    for (std::size_t f = 0; f < heights.size(); ++f) heights[f] = positions[f * joints + toe].y();
    const auto k = static_cast<std::size_t>(
        std::floor(options.ground_quantile * static_cast<double>(heights.size() - 1)));
    std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(k),
                     heights.end());
    model.ground_heights_[side] = heights[k];
  }

  // The captured feet, for the foot lock's plants.
  const int frames = response_clip.frame_count();
  model.captured_feet_.resize(static_cast<std::size_t>(frames) * 2);
  for (int f = 0; f < frames; ++f) {
    const int other = f > 0 ? f - 1 : std::min(1, frames - 1);
    for (std::size_t side = 0; side < 2; ++side) {
      const auto toe = static_cast<std::size_t>(response_roles[kToes[side]]);
      const Vec3& here = positions[static_cast<std::size_t>(f) * joints + toe];
      const Vec3& there = positions[static_cast<std::size_t>(other) * joints + toe];
      CapturedFoot& foot = model.captured_feet_[static_cast<std::size_t>(f) * 2 + side];
      foot.height_above_ground_m = static_cast<float>(here.y() - model.ground_heights_[side]);
      foot.speed_mps =
          static_cast<float>(horizontal_distance(here, there) * response_clip.frame_rate());
    }
  }
  model.captured_speed_p99_rad_s_ = largest_joint_speed_quantile(response_clip, 0.99);
  return model;
}

bool PartnerModel::foot_planted(int frame, Side side,
                                const FootLockParams& thresholds) const noexcept {
  const CapturedFoot& foot =
      captured_feet_[static_cast<std::size_t>(frame) * 2 + static_cast<std::size_t>(side)];
  return foot.height_above_ground_m <= thresholds.height_margin_m &&
         foot.speed_mps <= thresholds.speed_threshold_mps;
}

// ---------------------------------------------------------------------------------------------
// Parameters

bool parse_ik_target(std::string_view text, IkTarget& target) {
  if (text == "offset") {
    target = IkTarget::kCapturedOffset;
  } else if (text == "wrist") {
    target = IkTarget::kUserWrist;
  } else {
    return false;
  }
  return true;
}

const char* ik_target_name(IkTarget target) {
  return target == IkTarget::kCapturedOffset ? "offset" : "wrist";
}

std::string PartnerParams::validate() const {
  const std::pair<const char*, double> times[] = {
      {"smooth_rotation_half_life_s", smooth_rotation_half_life_s},
      {"smooth_translation_half_life_s", smooth_translation_half_life_s},
      {"blend_half_life_s", blend_half_life_s},
      {"blend_max_speed_rad_s", blend_max_speed_rad_s},
      {"blend_max_root_speed_mps", blend_max_root_speed_mps},
      {"ik_target_max_blend_speed_mps", ik_target_max_blend_speed_mps},
      {"ik_fade_s", ik_fade_s},
      {"ik_target_jump_speed_mps", ik_target_jump_speed_mps},
      {"reach_s", reach_s},
      {"blend_root_catch_up_rad_s", blend_root_catch_up_rad_s},
      {"foot.height_margin_m", foot.height_margin_m},
      {"foot.speed_threshold_mps", foot.speed_threshold_mps},
      {"foot.max_offset_m", foot.max_offset_m},
      {"foot.release_half_life_s", foot.release_half_life_s}};
  for (const auto& [name, value] : times) {
    if (!finite_time(value)) {
      return std::string(name) + " must be finite and >= 0 (got " + std::to_string(value) + ")";
    }
  }
  if (!(ik_correction_speed_budget_rad_s > 0.0) || !(ik_correction_min_speed_rad_s > 0.0)) {
    return "ik_correction_speed_budget_rad_s and ik_correction_min_speed_rad_s must be > 0 (got " +
           std::to_string(ik_correction_speed_budget_rad_s) + " and " +
           std::to_string(ik_correction_min_speed_rad_s) + ")";
  }
  if (!(ik_correction_max_speed_rad_s > 0.0)) {
    return "ik_correction_max_speed_rad_s must be > 0 (infinity for no limit; got " +
           std::to_string(ik_correction_max_speed_rad_s) + ")";
  }
  const std::pair<const char*, double> positive[] = {
      {"reach_fade_m", reach_fade_m}, {"reach_max_speed_rad_s", reach_max_speed_rad_s}};
  for (const auto& [name, value] : positive) {
    if (!(value > 0.0)) {
      return std::string(name) + " must be > 0 (got " + std::to_string(value) + ")";
    }
  }
  if (const std::string_view problem = user_filter.validate(); !problem.empty()) {
    return "user_filter: " + std::string(problem);
  }
  const std::pair<const char*, double> references[] = {
      {"user_facing_jitter_reference_rad", user_facing_jitter_reference_rad},
      {"facing_max_turn_rad_s", facing_max_turn_rad_s},
      {"ik_target_jitter_reference_m", ik_target_jitter_reference_m},
      {"ik_difference_time_constant_s", ik_difference_time_constant_s},
      {"ik_difference_power_time_constant_s", ik_difference_power_time_constant_s},
      {"ik_correction_clean_cutoff_hz", ik_correction_clean_cutoff_hz}};
  for (const auto& [name, value] : references) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      return std::string(name) + " must be finite and >= 0 (0: none; got " + std::to_string(value) +
             ")";
    }
  }
  if (!(ik_soft_reach >= 0.0 && ik_soft_reach < 1.0)) {
    return "ik_soft_reach must be within [0, 1) (0: none; got " + std::to_string(ik_soft_reach) +
           ")";
  }
  if (const std::string_view problem = ik_correction_filter.validate(); !problem.empty()) {
    return "ik_correction_filter: " + std::string(problem);
  }
  if (const std::string problem = foot_hold.validate(); !problem.empty()) return problem;
  if (const std::string_view problem = playhead.validate(); !problem.empty()) {
    return "playhead: " + std::string(problem);
  }
  return {};
}

namespace {

// The switch behind a correction's name; nullptr for an unknown name.
template <typename Params>
auto* correction_switch(Params& params, std::string_view name) noexcept {
  if (name == "align") return &params.align;
  if (name == "contact") return &params.contact;
  if (name == "smooth") return &params.smooth;
  if (name == "footlock") return &params.foot_lock;
  if (name == "blend") return &params.blend;
  if (name == "foothold") return &params.foot_hold.enabled;
  return static_cast<decltype(&params.align)>(nullptr);
}

}  // namespace

bool set_correction(PartnerParams& params, std::string_view name, bool enabled) noexcept {
  bool* value = correction_switch(params, name);
  if (value == nullptr) return false;
  *value = enabled;
  return true;
}

bool correction_enabled(const PartnerParams& params, std::string_view name) noexcept {
  const bool* value = correction_switch(params, name);
  return value != nullptr && *value;
}

std::string correction_names_list() {
  std::string s;
  for (const std::string_view name : kCorrectionNames) {
    if (!s.empty()) s += ", ";
    s += name;
  }
  return s;
}

Status parse_corrections(std::string_view list, PartnerParams& params) {
  PartnerParams out = params;
  for (const std::string_view name : kCorrectionNames) set_correction(out, name, false);
  while (!list.empty()) {
    const std::size_t comma = list.find(',');
    const std::string_view name = list.substr(0, comma);
    list = comma == std::string_view::npos ? std::string_view() : list.substr(comma + 1);
    if (name == "all") {
      for (const std::string_view each : kCorrectionNames) set_correction(out, each, true);
    } else if (name != "none" && !set_correction(out, name, true)) {
      return Error{"unknown correction '" + std::string(name) +
                   "' (known: " + correction_names_list() + ", all, none)"};
    }
  }
  params = out;
  return Ok{};
}

std::string corrections_string(const PartnerParams& params) {
  std::string s;
  for (const std::string_view name : kCorrectionNames) {
    if (!correction_enabled(params, name)) continue;
    if (!s.empty()) s += ',';
    s += name;
  }
  return s.empty() ? "none" : s;
}

// ---------------------------------------------------------------------------------------------
// Run time

double PartnerModel::spacing_scale(double user_height_m) const noexcept {
  const double captured = template_height_m_ + response_height_m_;
  if (!(user_height_m > 0.0) || !(template_height_m_ > 0.0) || !(response_height_m_ > 0.0)) {
    return 1.0;
  }
  return (user_height_m + response_height_m_) / captured;
}

UserPose user_pose_from_world(std::span<const Vec3> positions_ws,
                              std::span<const Quat> rotations_ws,
                              const JointRoles& roles) noexcept {
  UserPose user;
  if (positions_ws.empty() || rotations_ws.size() != positions_ws.size()) return user;
  user.root_position_ws = positions_ws[0];
  user.root_rotation_ws = rotations_ws[0];
  const auto n = static_cast<int>(positions_ws.size());
  const int left_hip = roles[Role::kLeftHip], right_hip = roles[Role::kRightHip];
  if (left_hip >= 0 && left_hip < n && right_hip >= 0 && right_hip < n && left_hip != right_hip) {
    user.body_heading = body_heading_frame(positions_ws, roles);
    user.body_heading_valid = user.body_heading.translation.allFinite() &&
                              user.body_heading.rotation.coeffs().allFinite();
  }
  for (const Side side : {Side::kLeft, Side::kRight}) {
    const int j = roles[side == Side::kLeft ? Role::kLeftWrist : Role::kRightWrist];
    if (j < 0 || static_cast<std::size_t>(j) >= positions_ws.size()) continue;
    user.wrist_positions_ws[static_cast<std::size_t>(side)] =
        positions_ws[static_cast<std::size_t>(j)];
    user.wrist_rotations_ws[static_cast<std::size_t>(side)] =
        rotations_ws[static_cast<std::size_t>(j)];
  }
  return user;
}

std::array<Quat, 2> hand_frame_turns(const Skeleton& user, const JointRoles& user_roles,
                                     const Skeleton& template_skeleton,
                                     const JointRoles& template_roles) {
  std::array<Quat, 2> turns = {Quat::Identity(), Quat::Identity()};
  const std::vector<Vec3> user_rest = rest_positions(user);
  const std::vector<Vec3> template_rest = rest_positions(template_skeleton);
  const auto forearm = [](const std::vector<Vec3>& rest, const JointRoles& roles, Side side,
                          Vec3& out) {
    const bool left = side == Side::kLeft;
    const int elbow = roles[left ? Role::kLeftElbow : Role::kRightElbow];
    const int wrist = roles[left ? Role::kLeftWrist : Role::kRightWrist];
    const auto n = static_cast<int>(rest.size());
    if (elbow < 0 || wrist < 0 || elbow >= n || wrist >= n) return false;
    out = rest[static_cast<std::size_t>(wrist)] - rest[static_cast<std::size_t>(elbow)];
    return out.norm() > 1e-9;
  };
  for (const Side side : {Side::kLeft, Side::kRight}) {
    Vec3 user_forearm, template_forearm;
    if (forearm(user_rest, user_roles, side, user_forearm) &&
        forearm(template_rest, template_roles, side, template_forearm)) {
      // R_template = R_user * turn: a template-frame vector along its rest forearm is, in the
      // user's hand frame, along the user's rest forearm.
      turns[static_cast<std::size_t>(side)] =
          Quat::FromTwoVectors(template_forearm, user_forearm).normalized();
    }
  }
  return turns;
}

void PartnerContext::resize(int joint_count) {
  const auto n = static_cast<std::size_t>(std::max(joint_count, 0));
  inertializer_.resize(joint_count);
  smoother_.resize(joint_count);
  blend_translations_.assign(n, Vec3::Zero());
  blend_rotations_.assign(n, Quat::Identity());
  positions_ws_.assign(n, Vec3::Zero());
  rotations_ws_.assign(n, Quat::Identity());
  reset();
}

double PartnerContext::captured_arm_turn(std::size_t hand, std::size_t joint,
                                         const Quat& captured) noexcept {
  Quat& previous = ik_captured_previous_[hand][joint];
  const double turn =
      ik_captured_previous_valid_[hand] ? log_map(previous.conjugate() * captured).norm() : 0.0;
  previous = captured;
  return turn;
}

// The jitter (radians) of the yaw of the facing the filter smooths (the user's raw facing, or with
// smooth_relative_to_template its turn from the template's), unwrapped so a turn through +-pi is
// no step.
double PartnerContext::facing_jitter(const Vec3& facing, double dt) noexcept {
  const double yaw = std::atan2(facing.x(), facing.z());
  if (!std::isfinite(yaw)) return user_facing_jitter_.rms();
  if (user_facing_yaw_valid_) {
    user_facing_yaw_ += wrap_angle(yaw - wrap_angle(user_facing_yaw_));
  } else {
    user_facing_yaw_ = yaw;
    user_facing_yaw_valid_ = true;
  }
  // A second difference over 0.5 rad (30 degrees in a frame) is a new user, not jitter.
  constexpr double kJitterTimeConstantS = 1.0, kMoveRad = 0.5;
  user_facing_jitter_.add(user_facing_yaw_, dt, kJitterTimeConstantS, kMoveRad);
  return user_facing_jitter_.rms();
}

Quat PartnerContext::capped_facing_turn(const Quat& turn, const Quat& template_rotation,
                                        const Quat& previous_template_rotation,
                                        double extra_rad) const noexcept {
  // The shown heading (turn * template) moves from last frame's by the template's own turn at
  // most, plus extra_rad: a user's facing read to turn 40 degrees in a frame (three points at an
  // improvised cut, a tracking glitch) turned the whole partner as fast (2629 deg/s).
  const double own = std::abs(
      wrap_angle(heading_yaw(template_rotation) - heading_yaw(previous_template_rotation)));
  const double last = heading_yaw(user_heading_.rotation);
  const double change = wrap_angle(heading_yaw(turn * template_rotation) - last);
  const double most = own + extra_rad;
  if (std::abs(change) <= most) return turn;
  return yaw_rotation(last + std::copysign(most, change)) * template_rotation.conjugate();
}

double PartnerContext::ik_target_jitter(std::size_t hand, const Vec3& target, double dt,
                                        bool restart) noexcept {
  // A second difference over 0.3 m in a frame is the target moving on, not jitter.
  constexpr double kMoveM = 0.3;
  return add_vector_jitter(ik_target_jitter_[hand], target, dt, kMoveM, restart);
}

Vec3 PartnerContext::steady_ik_target(std::size_t hand, const Vec3& target,
                                      const Vec3& captured_wrist, const Quat& body_rotation,
                                      const PartnerParams& p, double dt, bool restart) noexcept {
  const double jitter = ik_target_jitter(hand, target, dt, restart);
  const auto pair = static_cast<std::size_t>(ik_pair_[hand]);
  if (!target.allFinite() || !captured_wrist.allFinite() || pair >= ik_difference_.size()) {
    return target;
  }
  const Quat to_body = body_rotation.normalized().conjugate();
  const Vec3 difference_hs = to_body * (target - captured_wrist);
  return captured_wrist +
         body_rotation.normalized() * ik_difference_[pair].update(difference_hs, jitter,
                                                                  p.ik_target_jitter_reference_m,
                                                                  dt, steady_difference_params(p));
}

Quat PartnerContext::steady_hand_turn(std::size_t hand, const Quat& sensed, const Quat& captured,
                                      double offset_m, const PartnerParams& p, double dt,
                                      bool restart) noexcept {
  const auto pair = static_cast<std::size_t>(ik_pair_[hand]);
  const Quat from = captured.normalized();
  const Vec3 turn = log_map(from.conjugate() * sensed.normalized());
  if (!turn.allFinite() || pair >= ik_turn_difference_.size()) return sensed;
  // A second difference over 1.5 rad (86 degrees in a frame) is a move, not jitter: white noise
  // of 10 degrees per axis (4 per joint above the hand) gives second differences of 0.4 rad RMS.
  constexpr double kMoveRad = 1.5;
  const double jitter = add_vector_jitter(ik_turn_jitter_[hand], turn, dt, kMoveRad, restart);
  // The turn moves the target by about offset_m times its angle: the target's jitter reference
  // in radians. At least 1 cm of lever, so a zero offset does not divide by zero.
  const double reference_rad = p.ik_target_jitter_reference_m / std::max(offset_m, 0.01);
  return (from * exp_map(ik_turn_difference_[pair].update(turn, jitter, reference_rad,
                                                          dt, steady_difference_params(p))))
      .normalized();
}

double ik_correction_step_limit(const PartnerParams& p, double dt_s,
                                double captured_move_rad) noexcept {
  const double most = p.ik_correction_max_speed_rad_s * dt_s;
  if (!std::isfinite(captured_move_rad)) return most;
  const double least = std::min(p.ik_correction_min_speed_rad_s * dt_s, most);
  return std::clamp(p.ik_correction_speed_budget_rad_s * dt_s - captured_move_rad, least, most);
}

Vec3 step_within_turn(const Vec3& shown, const Vec3& wanted, double most_rad, const Quat& base,
                      const Quat& previous, double budget_rad, double least_rad) noexcept {
  const Vec3 full = step_towards(shown, wanted, most_rad);
  const auto turn = [&](const Vec3& correction) {
    return previous.angularDistance((base * exp_map(correction)).normalized());
  };
  // Kept as it was, the joint turns as the base does; the step may take it up to the budget,
  // or the base's own turn and the least more.
  const double allowed = std::max(budget_rad, turn(shown) + least_rad);
  if (!(turn(full) > allowed)) return full;
  // The turn grows with the share of the step taken near the answer: bisected.
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 12; ++i) {
    const double mid = 0.5 * (lo + hi);
    (turn(shown + mid * (full - shown)) > allowed ? hi : lo) = mid;
  }
  return shown + lo * (full - shown);
}

void PartnerContext::reset() noexcept {
  primed_ = false;
  inertializer_.reset();
  smoother_.reset();
  foot_locker_.reset();
  foot_hold_.reset();
  user_heading_ = Transform();
  user_root_filter_.reset();
  user_facing_filter_.reset();
  user_facing_jitter_.reset();
  user_facing_yaw_valid_ = false;
  for (auto& hand : ik_target_jitter_) {
    for (JitterMeter& meter : hand) meter.reset();
  }
  for (auto& hand : ik_turn_jitter_) {
    for (JitterMeter& meter : hand) meter.reset();
  }
  for (SteadyDifference& difference : ik_difference_) difference.reset();
  for (SteadyDifference& difference : ik_turn_difference_) difference.reset();
  for (auto& arm : ik_correction_filter_) {
    for (OneEuroFilter3& filter : arm) filter.reset();
  }
  ik_captured_previous_valid_ = {false, false};
  reach_shown_previous_valid_ = {false, false};
  hold_previous_valid_ = {false, false};
  for (auto& leg : hold_correction_) leg.fill(Vec3::Zero());
  ik_ramp_ = {0.0, 0.0};
  ik_pair_ = {-1, -1};
  ik_target_valid_ = {false, false};
  ik_target_offset_ = {Vec3::Zero(), Vec3::Zero()};
  ik_target_offset_velocity_ = {Vec3::Zero(), Vec3::Zero()};
  ik_target_half_life_ = {0.0, 0.0};
  detour_hs_ = Vec3::Zero();
  detour_offset_m_ = 0.0;
  detour_peak_ = 0.5;
  heading_is_relative_ = false;
  reach_ramp_ = {1.0, 1.0};
  for (auto& arm : reach_correction_) arm.fill(Vec3::Zero());
  blend_half_life_ = 0.0;
  blend_carrying_ = false;
}

std::string_view PartnerSynthesisJob::validate() const noexcept {
  if (model == nullptr) return "model is null";
  if (params == nullptr) return "params is null";
  if (context == nullptr) return "context is null";
  if (model->frame_count() <= 0 || !model->response_skeleton_ptr()) {
    return "model is empty (not built?)";
  }
  const auto n = static_cast<std::size_t>(model->response_skeleton().joint_count());
  if (context->joint_count() != static_cast<int>(n)) {
    return "context is not sized for the model's response skeleton";
  }
  if (frame < 0 || frame >= model->frame_count()) return "frame is outside the model's frames";
  if (translations_ls.size() != n) return "translations_ls does not have one entry per joint";
  if (rotations_ls.size() != n) return "rotations_ls does not have one entry per joint";
  if (translations_ls_out.size() != n)
    return "translations_ls_out does not have one entry per joint";
  if (rotations_ls_out.size() != n) return "rotations_ls_out does not have one entry per joint";
  if ((params->align || params->contact) && user == nullptr) {
    return "user is null (needed by align and contact)";
  }
  return {};
}

bool PartnerSynthesisJob::run() const noexcept {
  if (!validate().empty()) return false;
  const PartnerParams& p = *params;
  PartnerContext& ctx = *context;
  const Skeleton& skeleton = model->response_skeleton();
  const JointRoles& roles = model->response_roles();
  const double dt = dt_s > 0.0 && std::isfinite(dt_s) ? dt_s : 1.0 / model->frame_rate();
  const std::span<Vec3> out_t = translations_ls_out;
  const std::span<Quat> out_r = rotations_ls_out;
  // The real frame the pose was sampled at, for what is interpolated between frames.
  const bool has_position = frame_position >= 0.0 && std::isfinite(frame_position);
  PartnerFrameInfo diagnostics;
  diagnostics.contact_mask = model->contacts().mask(frame);

  if (out_t.data() != translations_ls.data()) {
    std::copy(translations_ls.begin(), translations_ls.end(), out_t.begin());
  }
  if (out_r.data() != rotations_ls.data()) {
    std::copy(rotations_ls.begin(), rotations_ls.end(), out_r.begin());
  }

  // 0. The user's heading frame, through the 1-euro filter when smoothing. With
  //    smooth_relative_to_template what is filtered is the user's heading relative to the
  //    template's at the partner's frame: the facing as a turn from the template's, the position
  //    as a shift from the template's pelvis (turned by that filtered turn). Both hold still while
  //    the user dances the template, turns and steps included, so the filter's lag falls on the
  //    noise and on the user's departures from the template, not on the dance itself.
  const bool user_root_finite = user != nullptr && user->root_position_ws.allFinite() &&
                                user->root_rotation_ws.coeffs().allFinite() &&
                                user->root_rotation_ws.norm() > 0.0;
  Transform user_heading = ctx.user_heading_;
  if (user_root_finite) {
    user_heading = user->body_heading_valid
                       ? user->body_heading
                       : heading_frame(user->root_position_ws, user->root_rotation_ws.normalized());
    if (p.smooth) {
      const bool relative = p.smooth_relative_to_template && p.align && has_position;
      Transform template_heading;  // the identity when not relative
      const Quat previous_template_rotation = ctx.template_rotation_;
      if (relative) {
        template_heading = model->alignment().template_heading_at(frame_position);
        // A taller user's steps are longer: the template's path scaled like the spacing.
        template_heading.translation *= model->spacing_scale(user->height_m);
        if (!ctx.heading_is_relative_) {
          ctx.user_facing_filter_.reset();
          ctx.user_root_filter_.reset();
        } else if (jumped) {
          // The template's heading changes at once at a jump; the heading shown must not: the
          // facing filter's turn becomes turn * d, d = old template heading * new one^-1 (turn *
          // d * new = turn * old), and the position filter is moved below.
          ctx.user_facing_filter_.rebase(
              ctx.template_rotation_ * template_heading.rotation.conjugate(), Vec3::Zero());
        }
        ctx.template_rotation_ = template_heading.rotation;
      } else if (ctx.heading_is_relative_) {
        ctx.user_facing_filter_.reset();
        ctx.user_root_filter_.reset();
      }
      const Vec3 facing =
          user_heading.rotation * template_heading.rotation.conjugate() * Vec3::UnitZ();
      OneEuroParams facing_filter = p.user_filter;
      if (p.user_facing_jitter_reference_rad > 0.0) {
        const double jitter = ctx.facing_jitter(facing, dt);
        const double ratio = jitter / p.user_facing_jitter_reference_rad;
        facing_filter.beta /= 1.0 + ratio * ratio;
      }
      const Vec3 smooth_facing = ctx.user_facing_filter_.filter(facing, dt, facing_filter);
      Quat turn = smooth_facing.norm() > 1e-6
                      ? yaw_rotation(std::atan2(smooth_facing.x(), smooth_facing.z()))
                      : yaw_rotation(std::atan2(facing.x(), facing.z()));
      if (relative && ctx.heading_is_relative_ && p.facing_max_turn_rad_s > 0.0) {
        turn =
            ctx.capped_facing_turn(turn, template_heading.rotation,
                                   jumped ? template_heading.rotation : previous_template_rotation,
                                   p.facing_max_turn_rad_s * dt);
      }
      const Vec3 template_position = turn * template_heading.translation;
      if (relative && ctx.heading_is_relative_ && jumped && ctx.user_root_filter_.primed()) {
        // ctx.user_heading_: the heading shown last frame (relative implies align).
        ctx.user_root_filter_.rebase(
            Quat::Identity(),
            ctx.user_heading_.translation - template_position - ctx.user_root_filter_.value());
      }
      ctx.heading_is_relative_ = relative;
      const Vec3 position = ctx.user_root_filter_.filter(
                                user_heading.translation - template_position, dt, p.user_filter) +
                            template_position;
      user_heading = {turn * template_heading.rotation, position};
    }
  }
  if (!p.smooth) {
    ctx.user_root_filter_.reset();
    ctx.user_facing_filter_.reset();
    ctx.heading_is_relative_ = false;
  }

  // 1. Align (5.1): the root relative to the user's heading frame.
  Transform heading;
  if (p.align) {
    if (user_root_finite) ctx.user_heading_ = user_heading;
    heading = ctx.user_heading_;
    const RootPlacement placement = has_position ? model->alignment().placement_at(frame_position)
                                                 : model->alignment().placement(frame);
    // The captured spacing, fitted to the user's body (a taller user stands further away).
    const double spacing = user != nullptr ? model->spacing_scale(user->height_m) : 1.0;
    const Transform root =
        heading * Transform{placement.rotation_hs, placement.spaced_position_hs(spacing)};
    out_t[0] = root.translation;
    out_r[0] = root.rotation.normalized();
  }

  // 2. Smooth (5.3): per joint, in quaternion space. At a jump that the blend will take, the
  //    smoother starts afresh from the new pose: the blend absorbs the whole jump at once, where a
  //    smoother catching up over the next frames would pass its catch-up through as a spike.
  if (p.blend && jumped) ctx.smoother_.reset();
  if (p.smooth) {
    ctx.smoother_.apply(out_t, out_r, p.smooth_rotation_half_life_s,
                        p.smooth_translation_half_life_s, dt, out_t, out_r);
  } else {
    ctx.smoother_.reset();
  }

  // 3. Foot lock (5.3): shift the root horizontally to hold planted feet.
  const std::array<bool, 2> planted = {model->foot_planted(frame, Side::kLeft, p.foot),
                                       model->foot_planted(frame, Side::kRight, p.foot)};
  const bool need_world = p.foot_lock || p.contact;
  if (need_world) {
    forward_kinematics(skeleton, out_t, out_r, ctx.positions_ws_, ctx.rotations_ws_);
  }
  //    While a blend carries the body to a new place (a jump, from its first frame), no foot is
  //    locked: a lock held then keeps the root up to FootLockParams::max_offset_m off the place
  //    the blend is bringing it to (PartnerParams::foot_lock_through_blend).
  Vec3 foot_lock_shift = Vec3::Zero();
  const bool carried_by_blend = p.blend && (jumped || ctx.blend_carrying_);
  if (p.foot_lock && (p.foot_lock_through_blend || !carried_by_blend)) {
    const std::array<Vec3, 2> feet = {ctx.positions_ws_[static_cast<std::size_t>(roles[kToes[0]])],
                                      ctx.positions_ws_[static_cast<std::size_t>(roles[kToes[1]])]};
    foot_lock_shift = ctx.foot_locker_.update(feet, planted, p.foot, dt);
    out_t[0] += foot_lock_shift;
    for (Vec3& position : ctx.positions_ws_) position += foot_lock_shift;
    diagnostics.foot_locked = {ctx.foot_locker_.locked(0), ctx.foot_locker_.locked(1)};
    diagnostics.foot_lock_offset_ws = foot_lock_shift;
  } else {
    ctx.foot_locker_.reset();
  }

  // 4. Contact (5.2): two-bone IK on each arm whose hand holds one of the user's, faded in/out.
  if (p.contact) {
    const HandContacts& contacts = model->contacts();
    const double step = p.ik_fade_s > 0.0 ? dt / p.ik_fade_s : 1.0;
    // The correction filter's cutoff falls as the arm's target's measured jitter grows (a
    // steady-state Kalman filter's gain goes as 1 / noise): ik_correction_clean_cutoff_hz on a
    // clean sensor, where the 1 Hz filter only lagged the correction (a 1.15x body's hands 1 cm
    // apart), the filter's own min_cutoff_hz from ik_target_jitter_reference_m up. The IK and
    // the release step the same filter state, so both use it.
    const bool steady = p.smooth && p.ik_target_jitter_reference_m > 0.0;
    const auto correction_filter_of = [&](std::size_t r) {
      OneEuroParams filter = p.ik_correction_filter;
      if (steady && p.ik_correction_clean_cutoff_hz > filter.min_cutoff_hz) {
        const double jitter = jitter_rms(ctx.ik_target_jitter_[r]);
        filter.min_cutoff_hz =
            jitter * p.ik_correction_clean_cutoff_hz >
                    filter.min_cutoff_hz * p.ik_target_jitter_reference_m
                ? std::max(filter.min_cutoff_hz,
                           filter.min_cutoff_hz * p.ik_target_jitter_reference_m / jitter)
                : p.ik_correction_clean_cutoff_hz;
      }
      return filter;
    };
    // An arm whose IK stops (its fade ended, the user's hand unknown this frame) lets its filtered
    // correction go the way it came, through the filter and at most ik_correction_max_speed_rad_s,
    // instead of in one frame: the correction lags the fading IK, and dropping what was left
    // swung the forearm of a partner of a user of other proportions at up to 2500 deg/s
    // (docs/evaluation.md, "The IK's correction let go"). At a blended jump the blend takes it.
    // Like the correction held, it takes only what the captured joint's own turn leaves of
    // the speed budget (ik_correction_step_limit).
    const auto release_correction = [&](std::size_t r) {
      std::array<OneEuroFilter3, 2>& filters = ctx.ik_correction_filter_[r];
      std::array<Vec3, 2>& shown = ctx.ik_correction_[r];
      constexpr double kReleasedRad = 1e-4;
      const bool holding = shown[0].norm() > kReleasedRad || shown[1].norm() > kReleasedRad;
      if (!p.smooth || (p.blend && jumped) || !filters[0].primed() || !filters[1].primed() ||
          !holding) {
        for (OneEuroFilter3& filter : filters) filter.reset();
        shown = {Vec3::Zero(), Vec3::Zero()};
        ctx.ik_captured_previous_valid_[r] = false;
        return;
      }
      const ArmRoles& arm = kArms[r];
      const std::array<std::size_t, 2> joints = {static_cast<std::size_t>(roles[arm.shoulder]),
                                                 static_cast<std::size_t>(roles[arm.elbow])};
      const OneEuroParams filter = correction_filter_of(r);
      for (std::size_t k = 0; k < 2; ++k) {
        const double captured_move = ctx.captured_arm_turn(r, k, out_r[joints[k]]);
        const Vec3 c = step_correction(filters[k], shown[k], Vec3::Zero(), Vec3::Zero(), dt, filter,
                                       ik_correction_step_limit(p, dt, captured_move));
        out_r[joints[k]] = (out_r[joints[k]] * exp_map(c)).normalized();
      }
      ctx.ik_captured_previous_valid_[r] = true;
    };
    for (std::size_t r = 0; r < 2; ++r) {
      // The template hand in contact with this response hand; the closer one if both are.
      int pair = -1;
      for (const Side ts : {Side::kLeft, Side::kRight}) {
        const int candidate = hand_pair(ts, static_cast<Side>(r));
        if (contacts.in_contact(frame, candidate) &&
            (pair < 0 || contacts.box_gap(frame, candidate) < contacts.box_gap(frame, pair))) {
          pair = candidate;
        }
      }
      const int previous_pair = ctx.ik_pair_[r];
      if (pair >= 0) ctx.ik_pair_[r] = pair;
      double ramp = ctx.ik_ramp_[r] + (pair >= 0 ? step : -step);
      ramp = ramp < 1e-9 ? 0.0 : (ramp > 1.0 - 1e-9 ? 1.0 : ramp);  // land exactly on 0 and 1
      // At a jump the blend (stage 5) takes the change of the finished pose, so the IK goes
      // straight to the new frame's state. A fade would play on after the blend started: a
      // contact left by a jump kept pulling the wrist towards a target made of the new frame's
      // captured offset (the dancers apart: far from the arm's pose) while the weight fell, and
      // swung the forearm at up to 3000 deg/s (docs/evaluation.md, "Partner metrics").
      if (p.blend && jumped) ramp = pair >= 0 ? 1.0 : 0.0;
      ctx.ik_ramp_[r] = ramp;
      const double weight = smoothstep(ctx.ik_ramp_[r]);
      if (weight <= 0.0 || ctx.ik_pair_[r] < 0) {
        release_correction(r);
        ctx.ik_target_valid_[r] = false;
        continue;
      }
      // During a fade-out the last contact's pair keeps driving the target, with the captured
      // offset of the current frame (stored for every frame), so a hand that lets go follows its
      // captured path while the weight falls.
      const Side ts = template_side(ctx.ik_pair_[r]);
      if (!finite_pose(*user, ts)) {
        release_correction(r);
        ctx.ik_target_valid_[r] = false;
        continue;
      }
      const auto t = static_cast<std::size_t>(ts);
      Vec3 raw_target = user->wrist_positions_ws[t];
      const bool target_restarts = jumped || ctx.ik_pair_[r] != previous_pair;
      if (p.ik_target == IkTarget::kCapturedOffset) {
        const double at = has_position ? frame_position : static_cast<double>(frame);
        const Vec3 offset = has_position ? contacts.offset_ls_at(frame_position, ctx.ik_pair_[r])
                                         : contacts.offset_ls(frame, ctx.ik_pair_[r]);
        Quat carried_by = user->wrist_rotations_ws[t].normalized();
        if (steady && p.align && p.steady_hand_turn) {
          // The offset is carried by the user's hand turned as the template's is, in the user's
          // heading, plus the steady difference of the sensed turn from it: under noise the
          // sensed hand's turn (the sum of every joint's noise above it) swung a 10-30 cm offset
          // by centimetres.
          const Quat template_hand =
              heading.rotation * model->alignment().template_heading_at(at).rotation.conjugate() *
              contacts.template_wrist_rotation_at(at, ts);
          carried_by = ctx.steady_hand_turn(r, carried_by, template_hand, offset.norm(), p, dt,
                                            target_restarts);
        }
        raw_target += carried_by * offset;
      }
      // The captured wrist moved by what the user's body alone changes (WristsOnUserBody): only
      // the rest of the sensed difference is averaged and doubted, and filtered (below). The
      // difference is taken from the captured wrist before the foot lock's shift: the shift is the
      // partner's own and known exactly, so the arm takes it whole.
      Vec3 expected =
          ctx.positions_ws_[static_cast<std::size_t>(roles[kArms[r].wrist])] - foot_lock_shift;
      const bool bodies_differ = p.align && !user->wrist_body_difference_hs[t].isZero();
      if (bodies_differ) expected += heading.rotation * user->wrist_body_difference_hs[t];
      if (steady) {
        raw_target = ctx.steady_ik_target(r, raw_target, expected,
                                          p.align ? heading.rotation : Quat::Identity(), p, dt,
                                          target_restarts);
      }
      // Keep the target continuous across jumps (5.3): the step of the raw target is absorbed
      // by an offset that decays like the blend. The speed test uses at least one model frame
      // as the interval, so a late frame followed by an early one is not taken for a jump.
      // At a jump the blend (stage 5) takes the whole change of the finished pose, IK
      // included, so the target goes straight to the new one.
      if (ctx.ik_target_valid_[r] && !(p.blend && jumped)) {
        const double interval = std::max(dt, 1.0 / model->frame_rate());
        const bool discontinuous =
            jumped || ctx.ik_pair_[r] != previous_pair ||
            (raw_target - ctx.ik_raw_target_[r]).norm() > p.ik_target_jump_speed_mps * interval;
        if (discontinuous) {
          ctx.ik_target_offset_[r] = ctx.ik_shown_target_[r] - raw_target;
          ctx.ik_target_half_life_[r] =
              capped_half_life(p.blend_half_life_s, ctx.ik_target_offset_[r].norm(),
                               p.ik_target_max_blend_speed_mps);
        } else {
          decay_spring_damper(ctx.ik_target_offset_[r], ctx.ik_target_offset_velocity_[r],
                              std::max(ctx.ik_target_half_life_[r], p.blend_half_life_s), dt);
        }
      } else {
        ctx.ik_target_offset_[r] = Vec3::Zero();
        ctx.ik_target_offset_velocity_[r] = Vec3::Zero();
      }
      const Vec3 target = raw_target + ctx.ik_target_offset_[r];
      ctx.ik_target_valid_[r] = true;
      ctx.ik_raw_target_[r] = raw_target;
      ctx.ik_shown_target_[r] = target;
      const ArmRoles& arm = kArms[r];
      const TwoBoneChain chain =
          chain_of(roles, arm.shoulder, arm.elbow, arm.wrist, ctx.positions_ws_, ctx.rotations_ws_);
      const Quat captured_start = out_r[chain.start], captured_mid = out_r[chain.mid];
      Quat ik_start = captured_start, ik_mid = captured_mid;
      Vec3 reached_at = Vec3::Zero();
      IkTwoBoneJob ik = chain_job(chain, captured_start, captured_mid, target);
      ik.weight = weight;
      ik.soft_reach = p.ik_soft_reach;
      ik.start_rotation_ls_out = &ik_start;
      ik.mid_rotation_ls_out = &ik_mid;
      ik.end_position_ws = &reached_at;
      if (!ik.run()) {
        release_correction(r);
        continue;
      }
      std::array<OneEuroFilter3, 2>& filters = ctx.ik_correction_filter_[r];
      if (!p.smooth || (p.blend && jumped)) {
        for (OneEuroFilter3& filter : filters) filter.reset();
      }
      if (p.smooth) {
        // The arm the bodies alone ask for (the captured arm reaching the expected target: as
        // smooth as the capture, no sensor in it) is taken whole.
        Quat base_start = captured_start, base_mid = captured_mid;
        if (bodies_differ) {
          IkTwoBoneJob base =
              chain_job(chain, captured_start, captured_mid, expected + ctx.ik_target_offset_[r]);
          base.weight = weight;
          base.soft_reach = p.ik_soft_reach;
          base.start_rotation_ls_out = &base_start;
          base.mid_rotation_ls_out = &base_mid;
          if (!base.run()) {
            base_start = captured_start;
            base_mid = captured_mid;
          }
        }
        // The correction (captured -> IK, in the joint's own frame): its part beyond the base arm
        // through the 1-euro filter, then put back on the captured rotation; the wrist lands
        // where that arm reaches. At most ik_correction_max_speed_rad_s: the IK adds at most that
        // to a joint's speed.
        std::array<Vec3, 2>& shown = ctx.ik_correction_[r];
        const OneEuroParams correction_filter = correction_filter_of(r);
        const auto correct = [&](std::size_t k, const Quat& captured, const Quat& base,
                                 const Quat& solved) {
          const double most =
              ik_correction_step_limit(p, dt, ctx.captured_arm_turn(r, k, captured));
          return step_correction(filters[k], shown[k], log_map(captured.conjugate() * solved),
                                 log_map(captured.conjugate() * base), dt, correction_filter, most);
        };
        const Vec3 start_correction = correct(0, captured_start, base_start, ik_start);
        const Vec3 mid_correction = correct(1, captured_mid, base_mid, ik_mid);
        ctx.ik_captured_previous_valid_[r] = true;
        ik_start = (captured_start * exp_map(start_correction)).normalized();
        ik_mid = (captured_mid * exp_map(mid_correction)).normalized();
        reached_at = arm_end_position(chain.start_ws, chain.mid_ws, chain.end_ws, captured_start,
                                      captured_mid, ik_start, ik_mid);
      }
      out_r[chain.start] = ik_start;
      out_r[chain.mid] = ik_mid;
      ctx.ik_reached_ws_[r] = reached_at;
      diagnostics.ik_weight[r] = weight;
      diagnostics.ik_target_ws[r] = target;
      diagnostics.ik_error_m[r] = (reached_at - target).norm();
    }
  } else {
    ctx.ik_ramp_ = {0.0, 0.0};
    ctx.ik_pair_ = {-1, -1};
    ctx.ik_target_valid_ = {false, false};
    for (auto& arm : ctx.ik_correction_filter_) {
      for (OneEuroFilter3& filter : arm) filter.reset();
    }
  }

  // 5. Blend (5.3): inertialization of the finished pose, so a jump's change is blended whatever
  //    stage made it (the response pose, the IK's target and weight, the foot lock's shift); an
  //    IK applied after the blend would snap the arms to the new pose in one frame. The root is
  //    blended relative to the user's heading frame (a jump keeps the partner with the user). The
  //    source of a transition is what was shown last frame.
  if (p.align) {
    const Transform root_hs = heading.inverse() * Transform{out_r[0], out_t[0]};
    out_t[0] = root_hs.translation;
    out_r[0] = root_hs.rotation.normalized();
  }
  if (p.blend) {
    if (jumped && ctx.primed_) {
      // A straight line from the place shown to the new one that passes through the user's body
      // (pelvis centres 0.14 m apart where the captured dancers were 0.60 m apart at the
      // closest) gets a detour: pushed sideways, away from the user, by what it lacks of
      // kKeepOutM, fullest where the line passes nearest (detour_share), none at both ends.
      ctx.detour_hs_ = Vec3::Zero();
      if (p.align) {
        const Vec3& from = ctx.blend_translations_[0];
        const Vec3& to = out_t[0];
        const double along = nearest_along_segment_2d(from, to);
        const Vec3 nearest = from + along * (to - from);
        const double lack = std::min(kKeepOutM, std::min(horizontal_distance(from, Vec3::Zero()),
                                                         horizontal_distance(to, Vec3::Zero()))) -
                            horizontal_distance(nearest, Vec3::Zero());
        if (lack > 0.0) {
          Vec3 side(nearest.x(), 0.0, nearest.z());
          if (side.norm() < 1e-3) side = Vec3(to.z() - from.z(), 0.0, from.x() - to.x());
          if (side.norm() > 1e-9) ctx.detour_hs_ = side.normalized() * lack;
          ctx.detour_peak_ = std::clamp(along, kDetourPeakRange[0], kDetourPeakRange[1]);
        }
      }
      ctx.inertializer_.transition(ctx.blend_translations_, ctx.blend_rotations_, out_t, out_r);
      ctx.detour_offset_m_ = ctx.inertializer_.root_translation_offset();
      ctx.blend_half_life_ =
          p.blend_speed_limited
              ? p.blend_half_life_s
              : std::max(
                    capped_half_life(p.blend_half_life_s, ctx.inertializer_.max_rotation_offset(),
                                     p.blend_max_speed_rad_s),
                    capped_half_life(p.blend_half_life_s,
                                     ctx.inertializer_.max_translation_offset(),
                                     p.blend_max_root_speed_mps));
    }
    PoseInertializer::Limits limits;
    if (p.blend_speed_limited) {
      limits.max_rotation_speed_rad_s = p.blend_max_speed_rad_s;
      limits.max_translation_speed_mps = p.blend_max_root_speed_mps;
      limits.limit_shown_speed = p.blend_no_faster_than_input;
      limits.root_catch_up_rad_s = p.blend_root_catch_up_rad_s;
    }
    ctx.inertializer_.update(out_t, out_r, std::max(ctx.blend_half_life_, p.blend_half_life_s), dt,
                             out_t, out_r, limits);
    diagnostics.blend_offset_rad = ctx.inertializer_.max_rotation_offset();
    ctx.blend_carrying_ = diagnostics.blend_offset_rad > kBlendingRad ||
                          ctx.inertializer_.max_translation_offset() > kBlendingM;
    if (!ctx.detour_hs_.isZero(0.0) && ctx.detour_offset_m_ > 0.0) {
      const double progress = std::clamp(
          1.0 - ctx.inertializer_.root_translation_offset() / ctx.detour_offset_m_, 0.0, 1.0);
      out_t[0] += ctx.detour_hs_ * detour_share(progress, ctx.detour_peak_);
      if (progress >= 1.0) ctx.detour_hs_ = Vec3::Zero();
    }
  } else {
    ctx.inertializer_.reset();
    ctx.blend_carrying_ = false;
  }
  std::copy(out_t.begin(), out_t.end(), ctx.blend_translations_.begin());
  std::copy(out_r.begin(), out_r.end(), ctx.blend_rotations_.begin());
  if (p.align) {
    const Transform root = heading * Transform{out_r[0], out_t[0]};
    out_t[0] = root.translation;
    out_r[0] = root.rotation.normalized();
  }

  // 5b. Reach (issue 11): through a jump's blend, an arm whose hand holds the user's reaches for
  //     it rather than waiting for the blend, which carries every joint at most
  //     blend_max_speed_rad_s and kept held hands apart for up to 0.7 s after jumps that barely
  //     moved the partner. A second IK on the blended pose, its weight rising from 0 at the jump
  //     over reach_s (so the arm does not snap) and falling with the distance the blend still
  //     holds the wrist from where the contact stage put it (so it fades out with the blend).
  //     What it adds to each arm joint changes at most reach_max_speed_rad_s, also when it ends,
  //     and turns the joint no faster than the captured partner's p99 speed (step_within_turn).
  if (p.contact && p.blend && p.reach_s > 0.0) {
    const double rise = dt / p.reach_s;
    // The arm turns no faster than the captured partner's fastest joint on 99 % of its frames
    // (the blend's own turn aside): a reach along the blend no longer adds its whole speed to it.
    const double reach_budget = model->captured_speed_p99_rad_s();
    const bool blending = ctx.blend_carrying_;
    bool posed = false;
    for (std::size_t r = 0; r < 2; ++r) {
      std::array<Vec3, 2>& shown = ctx.reach_correction_[r];
      // A jump restarts the reach; the blend's transition (from the pose shown, reach included)
      // takes what it had added.
      if (jumped) shown.fill(Vec3::Zero());
      const ArmRoles& arm = kArms[r];
      const std::array<std::size_t, 2> joints = {static_cast<std::size_t>(roles[arm.shoulder]),
                                                 static_cast<std::size_t>(roles[arm.elbow])};
      const bool turned_before = ctx.reach_shown_previous_valid_[r];
      ctx.reach_shown_previous_valid_[r] = true;
      ctx.reach_ramp_[r] = jumped ? 0.0 : std::min(1.0, ctx.reach_ramp_[r] + rise);
      const bool reaching = blending && diagnostics.ik_weight[r] > 0.0 && ctx.reach_ramp_[r] > 0.0;
      if (!reaching && shown[0].isZero(0.0) && shown[1].isZero(0.0)) {
        for (std::size_t k = 0; k < 2; ++k) ctx.reach_shown_previous_[r][k] = out_r[joints[k]];
        continue;
      }
      if (!posed) {
        forward_kinematics(skeleton, out_t, out_r, ctx.positions_ws_, ctx.rotations_ws_);
        posed = true;
      }
      const TwoBoneChain chain =
          chain_of(roles, arm.shoulder, arm.elbow, arm.wrist, ctx.positions_ws_, ctx.rotations_ws_);
      std::array<Quat, 2> solved = {out_r[chain.start], out_r[chain.mid]};
      if (reaching) {
        const Vec3& target = ctx.ik_shown_target_[r];
        const double gap = (chain.end_ws.translation - ctx.ik_reached_ws_[r]).norm();
        const double reach = (chain.mid_ws.translation - chain.start_ws.translation).norm() +
                             (chain.end_ws.translation - chain.mid_ws.translation).norm();
        const double weight =
            smoothstep(ctx.reach_ramp_[r]) * smoothstep(std::min(1.0, gap / p.reach_fade_m));
        // A target out of the arm's reach (the partner still crossing to its place) would only
        // stretch the arm straight.
        if (weight > 0.0 && (target - chain.start_ws.translation).norm() < reach) {
          IkTwoBoneJob ik = chain_job(chain, solved[0], solved[1], target);
          ik.weight = weight;
          ik.soft_reach = p.ik_soft_reach;
          ik.start_rotation_ls_out = &solved[0];
          ik.mid_rotation_ls_out = &solved[1];
          if (!ik.run()) solved = {out_r[chain.start], out_r[chain.mid]};
        }
      }
      for (std::size_t k = 0; k < 2; ++k) {
        const Vec3 wanted = log_map(out_r[joints[k]].conjugate() * solved[k]);
        const double most = p.reach_max_speed_rad_s * dt;
        shown[k] = turned_before
                       ? step_within_turn(shown[k], wanted, most, out_r[joints[k]],
                                          ctx.reach_shown_previous_[r][k], reach_budget * dt,
                                          p.ik_correction_min_speed_rad_s * dt)
                       : step_towards(shown[k], wanted, most);
        out_r[joints[k]] = (out_r[joints[k]] * exp_map(shown[k])).normalized();
        ctx.blend_rotations_[joints[k]] = out_r[joints[k]];  // the pose shown
        ctx.reach_shown_previous_[r][k] = out_r[joints[k]];
      }
    }
  } else {
    ctx.reach_ramp_ = {1.0, 1.0};
    ctx.reach_shown_previous_valid_ = {false, false};
    for (auto& arm : ctx.reach_correction_) arm.fill(Vec3::Zero());
  }

  // 6. Foot hold (issue 11): through a jump's blend, planted feet stay where they stand and the
  //    legs reach them by two-bone IK; the pose catches up by steps (foot_hold.h). After the blend
  //    (which carries the root and every leg joint to the new frame's pose, sliding the feet).
  if (p.foot_lock && p.blend && p.foot_hold.enabled && model->has_legs()) {
    forward_kinematics(skeleton, out_t, out_r, ctx.positions_ws_, ctx.rotations_ws_);
    // Per leg, its joints (hip, knee, ankle).
    std::array<std::array<std::size_t, 3>, 2> leg_joints;
    for (std::size_t side = 0; side < 2; ++side) {
      const LegRoles& leg = kLegs[side];
      leg_joints[side] = {static_cast<std::size_t>(roles[leg.hip]),
                          static_cast<std::size_t>(roles[leg.knee]),
                          static_cast<std::size_t>(roles[leg.ankle])};
    }
    std::array<Vec3, 2> ankles, hips;
    std::array<Quat, 2> ankle_rotations;
    std::array<double, 2> leg_lengths;
    for (std::size_t side = 0; side < 2; ++side) {
      const auto [hip, knee, ankle] = leg_joints[side];
      ankles[side] = ctx.positions_ws_[ankle];
      ankle_rotations[side] = ctx.rotations_ws_[ankle];
      hips[side] = ctx.positions_ws_[hip];
      leg_lengths[side] = (ctx.positions_ws_[knee] - hips[side]).norm() +
                          (ankles[side] - ctx.positions_ws_[knee]).norm();
    }
    const bool blending = ctx.blend_carrying_;
    ctx.foot_hold_.update(ankles, ankle_rotations, hips, leg_lengths, planted, blending,
                          jumped && blending, p.foot_hold, dt);
    // Per leg, its joints' rotations before the hold.
    std::array<std::array<Quat, 3>, 2> leg_base;
    for (std::size_t side = 0; side < 2; ++side) {
      for (std::size_t k = 0; k < 3; ++k) leg_base[side][k] = out_r[leg_joints[side][k]];
    }
    bool any = false;
    for (std::size_t side = 0; side < 2; ++side) {
      const FootHoldTarget& target = ctx.foot_hold_.target(static_cast<int>(side));
      if (!target.active) continue;
      const LegRoles& leg = kLegs[side];
      const TwoBoneChain chain =
          chain_of(roles, leg.hip, leg.knee, leg.ankle, ctx.positions_ws_, ctx.rotations_ws_);
      const Quat hip_before = out_r[chain.start], knee_before = out_r[chain.mid];
      IkTwoBoneJob ik = chain_job(chain, hip_before, knee_before, target.position_ws);
      ik.start_rotation_ls_out = &out_r[chain.start];
      ik.mid_rotation_ls_out = &out_r[chain.mid];
      any = ik.run() || any;
    }
    if (any) {
      // The ankles' world rotations: the pose's, turned to the held heading.
      forward_kinematics(skeleton, out_t, out_r, ctx.positions_ws_, ctx.rotations_ws_);
      for (std::size_t side = 0; side < 2; ++side) {
        const FootHoldTarget& target = ctx.foot_hold_.target(static_cast<int>(side));
        if (!target.active) continue;
        const auto ja = static_cast<std::size_t>(roles[kLegs[side].ankle]);
        const auto parent = static_cast<std::size_t>(skeleton.joints[ja].parent);
        out_r[ja] = (ctx.rotations_ws_[parent].conjugate() * target.turn_ws * ankle_rotations[side])
                        .normalized();
      }
    }
    // What the hold changed on each leg joint, shown within the speed budget (step_within_turn):
    // a step no longer swings the leg faster than the capture does.
    const double most = std::numeric_limits<double>::infinity();
    for (std::size_t side = 0; side < 2; ++side) {
      const std::array<std::size_t, 3>& joints = leg_joints[side];
      for (std::size_t k = 0; k < 3; ++k) {
        const Quat& base = leg_base[side][k];
        const Vec3 wanted = log_map(base.conjugate() * out_r[joints[k]]);
        Vec3& shown = ctx.hold_correction_[side][k];
        shown = ctx.hold_previous_valid_[side]
                    ? step_within_turn(shown, wanted, most, base, ctx.hold_previous_[side][k],
                                       p.foot_hold.speed_budget_rad_s * dt,
                                       p.foot_hold.least_speed_rad_s * dt)
                    : wanted;
        out_r[joints[k]] = (base * exp_map(shown)).normalized();
        ctx.hold_previous_[side][k] = out_r[joints[k]];
      }
      ctx.hold_previous_valid_[side] = true;
    }
    diagnostics.foot_held = {ctx.foot_hold_.held(0), ctx.foot_hold_.held(1)};
  } else {
    ctx.foot_hold_.reset();
    ctx.hold_previous_valid_ = {false, false};
    for (auto& leg : ctx.hold_correction_) leg.fill(Vec3::Zero());
  }

  ctx.primed_ = true;
  if (info != nullptr) *info = diagnostics;
  return true;
}

}  // namespace duet
