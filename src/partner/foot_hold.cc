#include "duet/partner/foot_hold.h"

#include "duet/math/rotation.h"

#include <algorithm>
#include <cmath>

namespace duet {
namespace {

// Once the blend is over, a held foot this close to where the pose puts it is let go.
constexpr double kCaughtUpM = 0.005;
// A step's horizontal crossing (a smoothstep over this part of the step): it starts as the foot
// rises and ends before it lands. Over 0.15-0.75 of the step the foot crossed at up to 7 m/s and
// swung the legs faster than the capture (p99 largest joint speed 742 deg/s on improv-pause).
constexpr double kCrossBegin = 0.1, kCrossLength = 0.8;
// How much further than the pose itself a held foot may stretch a leg that is already beyond
// reach_fraction in the pose.
constexpr double kReachSlackM = 0.01;
// Slower than this the body counts as standing (a foot left behind steps whatever the direction).
constexpr double kStillMps = 0.3;

double smoothstep01(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

// The angle of the turn about the world vertical contained in q (its twist about Y), in
// (-pi, pi].
double heading_angle(const Quat& q) {
  if (!(std::hypot(q.w(), q.y()) > 1e-9)) return 0.0;
  return wrap_angle(2.0 * std::atan2(q.y(), q.w()));
}

// `angle` (wrapped) taken the way round nearest to `previous` (unwrapped).
double unwrap(double angle, double previous) { return previous + wrap_angle(angle - previous); }

}  // namespace

std::string FootHoldParams::validate() const {
  const std::pair<const char*, double> values[] = {{"foot_hold.step_trigger_m", step_trigger_m},
                                                   {"foot_hold.step_time_s", step_time_s},
                                                   {"foot_hold.step_height_m", step_height_m},
                                                   {"foot_hold.reach_fraction", reach_fraction},
                                                   {"foot_hold.step_lead_s", step_lead_s}};
  for (const auto& [name, value] : values) {
    if (!(value >= 0.0 && std::isfinite(value))) {
      return std::string(name) + " must be finite and >= 0 (got " + std::to_string(value) + ")";
    }
  }
  if (!(speed_budget_rad_s > 0.0) || !(least_speed_rad_s > 0.0)) {
    return "foot_hold.speed_budget_rad_s and foot_hold.least_speed_rad_s must be > 0 (got " +
           std::to_string(speed_budget_rad_s) + " and " + std::to_string(least_speed_rad_s) + ")";
  }
  return {};
}

void FootHold::reset() noexcept { *this = FootHold(); }

void FootHold::hold(Foot& foot, const Vec3& point, const Quat& rotation) noexcept {
  foot.state = kHeld;
  foot.point = point;
  foot.rotation = rotation;
  foot.heading = 0.0;
}

void FootHold::start_step(Foot& foot, double lift_m) noexcept {
  // The step starts from the held point and rotation (foot.point, foot.rotation).
  foot.state = kStepping;
  foot.progress = 0.0;
  foot.lift_m = lift_m;
  foot.landing_fixed = false;
}

void FootHold::update(const std::array<Vec3, 2>& ankles_ws,
                      const std::array<Quat, 2>& ankle_rotations_ws,
                      const std::array<Vec3, 2>& hips_ws,
                      const std::array<double, 2>& leg_lengths_m,
                      const std::array<bool, 2>& planted, bool blending, bool jumped,
                      const FootHoldParams& params, double dt_s) noexcept {
  // The body's horizontal velocity (the hips' midpoint, lightly low-passed), for where steps land.
  const Vec3 centre = 0.5 * (hips_ws[0] + hips_ws[1]);
  if (centre.allFinite() && has_centre_ && dt_s > 0.0) {
    const Vec3 velocity = (centre - centre_) / dt_s;
    body_velocity_ += 0.5 * (Vec3(velocity.x(), 0.0, velocity.z()) - body_velocity_);
  }
  has_centre_ = centre.allFinite();
  centre_ = has_centre_ ? centre : Vec3::Zero();
  if (!body_velocity_.allFinite() || !has_centre_) body_velocity_.setZero();
  const double body_speed = body_velocity_.norm();

  for (std::size_t i = 0; i < 2; ++i) {
    Foot& foot = feet_[i];
    FootHoldTarget& out = targets_[i];
    const Vec3& pose = ankles_ws[i];
    const Quat& rotation = ankle_rotations_ws[i];
    if (!params.enabled || !pose.allFinite() || !rotation.coeffs().allFinite() ||
        !(rotation.norm() > 0.0)) {
      foot = Foot();
      out = FootHoldTarget();
      shown_valid_[i] = false;
      continue;
    }
    const bool has_shown = shown_valid_[i];
    shown_valid_[i] = true;
    const bool other_stepping = feet_[1 - i].state == kStepping;
    const double behind = horizontal_distance(foot.point, pose);
    const Vec3 held_at(foot.point.x(), pose.y(), foot.point.z());
    const double reach = params.reach_fraction * leg_lengths_m[i];
    // Out of reach: stretched beyond that share of the leg, and further than the pose stretches
    // it (a standing pose's leg may be straighter than that already).
    const bool out_of_reach =
        hips_ws[i].allFinite() &&
        (held_at - hips_ws[i]).norm() > std::max(reach, (pose - hips_ws[i]).norm() + kReachSlackM);
    // Left behind: the pose has gone on past the held foot in the body's direction of travel
    // (a foot that landed ahead waits for the body to pass it).
    const Vec3 ahead = pose - foot.point;
    const bool left_behind =
        behind > params.step_trigger_m &&
        (body_speed < kStillMps || ahead.x() * body_velocity_.x() + ahead.z() * body_velocity_.z() > 0.0);
    switch (foot.state) {
      case kFree:
        // At the jump itself every foot: one the new frame has swinging would otherwise be carried
        // by the blend before it lifts.
        if (blending && (planted[i] || jumped)) {
          // At the jump, where it was shown last frame: this frame's pose has already taken the
          // blend's first step.
          if (jumped && has_shown) {
            hold(foot, shown_[i], shown_rotations_[i]);
          } else {
            hold(foot, pose, rotation);
          }
          if (!planted[i]) start_step(foot, params.step_height_m);
        }
        break;
      case kHeld:
        if (!planted[i]) {
          // The captured foot lifts: a step to where the pose has it (crossing at floor level
          // with the capture's own swing dragged it whenever the capture's plant flickered).
          start_step(foot, params.step_height_m);
        } else if (out_of_reach ||
                   (left_behind && (!other_stepping || behind > 2.0 * params.step_trigger_m))) {
          start_step(foot, params.step_height_m);
        } else if (!blending) {
          // The blend is over: let go where the pose has caught up, else one step there (a hold
          // kept on through the dance after it twisted the leg ever further from the pose).
          if (behind < kCaughtUpM) {
            foot.state = kFree;
          } else if (!other_stepping) {
            start_step(foot, params.step_height_m);
          }
        }
        break;
      case kStepping:
        // A step at floor level (after a landing, following the capture's swing) whose captured
        // foot plants again before it arrives: crossing on along the floor slid the foot (29 of
        // the 140 jumps with a planted toe over 0.3 m/s; docs/evaluation.md, "No step along the
        // floor"). It is held where it is shown and the rest is a step of its own.
        if (foot.lift_m <= 0.0 && planted[i] && has_shown) {
          hold(foot, shown_[i], shown_rotations_[i]);
          if (horizontal_distance(foot.point, pose) > kCaughtUpM) {
            start_step(foot, params.step_height_m);
          } else {
            foot.state = kFree;
          }
        }
        break;
    }

    if (foot.state == kFree) {
      out = FootHoldTarget();
      shown_[i] = pose;
      shown_rotations_[i] = rotation;
      continue;
    }
    out.active = true;
    if (foot.state == kHeld) {
      out.position_ws = Vec3(foot.point.x(), pose.y(), foot.point.z());
      foot.heading = unwrap(heading_angle(foot.rotation * rotation.conjugate()), foot.heading);
      out.turn_ws = yaw_rotation(foot.heading);
      shown_[i] = out.position_ws;
      shown_rotations_[i] = (out.turn_ws * rotation).normalized();
      continue;
    }

    // Stepping: rise, cross to where the pose puts the foot, land.
    const double step = params.step_time_s > 0.0 ? dt_s / params.step_time_s : 1.0;
    foot.progress = std::min(1.0, foot.progress + (step > 0.0 ? step : 0.0));
    const double s = foot.progress;
    const double cross = smoothstep01((s - kCrossBegin) / kCrossLength);
    Vec3 end = pose;
    if (foot.lift_m > 0.0 && !foot.landing_fixed) {
      // Land ahead of the pose by the body's travel over step_lead_s, within the leg's reach of
      // the hip, so that the body passes over the foot instead of leaving it behind at once.
      end += body_velocity_ * params.step_lead_s;
      if (hips_ws[i].allFinite()) {
        const double dy = hips_ws[i].y() - pose.y();
        const double most = 0.9 * std::sqrt(std::max(0.0, reach * reach - dy * dy));
        const Vec3 from_hip(end.x() - hips_ws[i].x(), 0.0, end.z() - hips_ws[i].z());
        if (from_hip.norm() > most) {
          end = Vec3(hips_ws[i].x(), end.y(), hips_ws[i].z()) + from_hip * (most / from_hip.norm());
        }
      }
    }
    if (foot.lift_m > 0.0) {
      // A step of its own lands where the pose was when the crossing ended, and is held there
      // (following the pose on to the ground would slide it).
      if (cross >= 1.0 && !foot.landing_fixed) {
        foot.landing = end;
        foot.landing_fixed = true;
      }
      if (foot.landing_fixed) end = foot.landing;
    }
    const Vec3 across = foot.point + (end - foot.point) * cross;
    out.position_ws = Vec3(across.x(), pose.y() + foot.lift_m * std::sin(kPi * s), across.z());
    // The heading turns back with the crossing, the way round it has turned while held (at half
    // a turn the shorter way flips from one frame to the next).
    foot.heading = unwrap(heading_angle(foot.rotation * rotation.conjugate()), foot.heading);
    out.turn_ws = yaw_rotation(foot.heading * (1.0 - cross));
    shown_[i] = out.position_ws;
    shown_rotations_[i] = (out.turn_ws * rotation).normalized();
    if (s < 1.0) continue;
    if (foot.lift_m <= 0.0) {
      foot.state = kFree;  // released: the target is the pose itself now
    } else {
      hold(foot, out.position_ws, (out.turn_ws * rotation).normalized());
      // The captured foot is in the air: on to where the pose has it (its swing lifts it).
      if (!planted[i]) start_step(foot, 0.0);
    }
  }
}

}  // namespace duet
