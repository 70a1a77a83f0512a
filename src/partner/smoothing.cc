#include "duet/partner/smoothing.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "duet/math/rotation.h"

namespace duet {

double half_life_alpha(double half_life_s, double dt_s) noexcept {
  if (!(dt_s > 0.0)) return 0.0;  // also catches NaN
  if (!(half_life_s > 0.0) || !std::isfinite(half_life_s)) return 1.0;
  if (!std::isfinite(dt_s)) return 1.0;
  return 1.0 - std::exp2(-dt_s / half_life_s);
}

Quat smooth_rotation(const Quat& current, const Quat& target, double half_life_s,
                     double dt_s) noexcept {
  const double alpha = half_life_alpha(half_life_s, dt_s);
  if (alpha >= 1.0) return target;
  if (alpha <= 0.0) return current;
  // Eigen's slerp takes the shortest arc (it flips the sign of the second quaternion if needed).
  return current.slerp(alpha, target).normalized();
}

Vec3 smooth_position(const Vec3& current, const Vec3& target, double half_life_s,
                     double dt_s) noexcept {
  const double alpha = half_life_alpha(half_life_s, dt_s);
  if (alpha >= 1.0) return target;
  return current + alpha * (target - current);
}

namespace {

// Holds a decaying offset's step since `before` to at most max_speed * dt (the spring's velocity
// with it), so a large offset moves at that speed until the spring alone is slower.
void limit_speed(Vec3& x, Vec3& v, const Vec3& before, double max_speed, double dt) {
  if (!(max_speed > 0.0) || !std::isfinite(max_speed)) return;
  const Vec3 step = x - before;
  const double length = step.norm();
  if (length <= max_speed * dt) return;
  x = before + step * (max_speed * dt / length);
  const double speed = v.norm();
  if (speed > max_speed) v *= max_speed / speed;
}

// The constants of one decay step, computed once per frame for all joints.
struct DecayStep {
  bool skip = false;     // dt <= 0: nothing happens
  bool instant = false;  // no half-life: the offset vanishes at once
  double y = 0.0;
  double eydt = 1.0;
  double dt = 0.0;

  DecayStep(double half_life_s, double dt_s) {
    if (!(dt_s > 0.0)) {
      skip = true;
    } else if (!(half_life_s > 0.0) || !std::isfinite(half_life_s) || !std::isfinite(dt_s)) {
      instant = true;
    } else {
      // Holden, spring.h: damping = 4 ln 2 / half_life, y = damping / 2 for a critically damped
      // spring; the closed form below is exact for any dt.
      y = 2.0 * std::log(2.0) / half_life_s;
      eydt = std::exp(-y * dt_s);
      dt = dt_s;
    }
  }

  void apply(Vec3& x, Vec3& v) const {
    if (skip) return;
    if (instant) {
      x.setZero();
      v.setZero();
      return;
    }
    const Vec3 j1 = v + x * y;
    x = eydt * (x + j1 * dt);
    v = eydt * (v - j1 * (y * dt));
  }
};

// The angle of the rotation from `from` to `to`, radians (the shorter way round).
double rotation_angle(const Quat& from, const Quat& to) {
  const double dot = std::abs(from.dot(to));
  return 2.0 * std::acos(std::min(dot, 1.0));
}

// Holds a rotation offset's step since `before` back so that the joint shown (offset * input)
// turns from the pose shown last no faster than the input itself or `max_speed`, whichever is
// faster, plus `catch_up`. Holding the offset (s = 0) turns it exactly as fast as the input
// (conjugation keeps the angle), so the largest s in [0, 1] within the limit exists; found by
// bisection. The shown turn is at most the input's turn plus the offset's step (the exponential map
// shortens distances), which settles most joints without a search; steps under kNegligibleRad (a
// decayed offset's tail) are not checked.
void limit_output_speed(Vec3& x, Vec3& v, const Vec3& before, const Quat& input,
                        const Quat& previous_input, const Quat& previous_output, double max_speed,
                        double dt, double catch_up) {
  constexpr double kNegligibleRad = 1e-6;
  const double step = (x - before).norm();
  if (step <= kNegligibleRad) return;
  const double input_turn = rotation_angle(previous_input, input);
  const double limit = std::max(input_turn + catch_up * dt, max_speed * dt);
  if (input_turn + step <= limit) return;
  const auto shown_turn = [&](double s) {
    return rotation_angle(previous_output, exp_map(before + s * (x - before)) * input);
  };
  if (shown_turn(1.0) <= limit) return;
  double low = 0.0, high = 1.0;
  for (int i = 0; i < 8; ++i) {
    const double mid = 0.5 * (low + high);
    (shown_turn(mid) <= limit ? low : high) = mid;
  }
  x = before + low * (x - before);
  v *= low;
}

}  // namespace

void decay_spring_damper(Vec3& x, Vec3& v, double half_life_s, double dt_s) noexcept {
  DecayStep(half_life_s, dt_s).apply(x, v);
}

void PoseSmoother::resize(int joint_count) {
  const auto n = static_cast<std::size_t>(std::max(joint_count, 0));
  translations_.assign(n, Vec3::Zero());
  rotations_.assign(n, Quat::Identity());
  primed_ = false;
}

void PoseSmoother::apply(std::span<const Vec3> translations_ls, std::span<const Quat> rotations_ls,
                         double rotation_half_life_s, double translation_half_life_s, double dt_s,
                         std::span<Vec3> translations_out, std::span<Quat> rotations_out) noexcept {
  const std::size_t n = rotations_.size();
  assert(translations_ls.size() == n && rotations_ls.size() == n);
  assert(translations_out.size() == n && rotations_out.size() == n);
  if (!primed_) {
    std::copy(translations_ls.begin(), translations_ls.end(), translations_.begin());
    std::copy(rotations_ls.begin(), rotations_ls.end(), rotations_.begin());
    primed_ = true;
  } else {
    const double ar = half_life_alpha(rotation_half_life_s, dt_s);
    const double at = half_life_alpha(translation_half_life_s, dt_s);
    for (std::size_t j = 0; j < n; ++j) {
      rotations_[j] = ar >= 1.0 ? rotations_ls[j] : rotations_[j].slerp(ar, rotations_ls[j]);
      rotations_[j].normalize();
      translations_[j] += at * (translations_ls[j] - translations_[j]);
    }
  }
  std::copy(translations_.begin(), translations_.end(), translations_out.begin());
  std::copy(rotations_.begin(), rotations_.end(), rotations_out.begin());
}

void PoseInertializer::resize(int joint_count) {
  const auto n = static_cast<std::size_t>(std::max(joint_count, 0));
  rotation_x_.assign(n, Vec3::Zero());
  rotation_v_.assign(n, Vec3::Zero());
  translation_x_.assign(n, Vec3::Zero());
  translation_v_.assign(n, Vec3::Zero());
  previous_input_.assign(n, Quat::Identity());
  previous_output_.assign(n, Quat::Identity());
  has_previous_ = false;
}

void PoseInertializer::reset() noexcept {
  for (auto* buffer : {&rotation_x_, &rotation_v_, &translation_x_, &translation_v_}) {
    std::fill(buffer->begin(), buffer->end(), Vec3::Zero());
  }
  has_previous_ = false;
}

void PoseInertializer::transition(std::span<const Vec3> source_translations_ls,
                                  std::span<const Quat> source_rotations_ls,
                                  std::span<const Vec3> destination_translations_ls,
                                  std::span<const Quat> destination_rotations_ls) noexcept {
  const std::size_t n = rotation_x_.size();
  assert(source_translations_ls.size() == n && source_rotations_ls.size() == n);
  assert(destination_translations_ls.size() == n && destination_rotations_ls.size() == n);
  for (std::size_t j = 0; j < n; ++j) {
    // The source already includes the previous offset, so the new offset replaces it (Holden:
    // off_x = (src_x + off_x) - dst_x with src_x + off_x being the pose shown).
    rotation_x_[j] = log_map(source_rotations_ls[j] * destination_rotations_ls[j].conjugate());
    translation_x_[j] = source_translations_ls[j] - destination_translations_ls[j];
    // The cut is no motion of the input: its speed counts from the new pose on.
    previous_input_[j] = destination_rotations_ls[j];
    previous_output_[j] = source_rotations_ls[j];
  }
  has_previous_ = true;
}

void PoseInertializer::update(std::span<const Vec3> translations_ls,
                              std::span<const Quat> rotations_ls, double half_life_s, double dt_s,
                              std::span<Vec3> translations_out, std::span<Quat> rotations_out,
                              const Limits& limits) noexcept {
  const std::size_t n = rotation_x_.size();
  assert(translations_ls.size() == n && rotations_ls.size() == n);
  assert(translations_out.size() == n && rotations_out.size() == n);
  const DecayStep decay(half_life_s, dt_s);
  const bool timed = dt_s > 0.0 && std::isfinite(dt_s);
  const double max_rotation_speed = limits.max_rotation_speed_rad_s;
  const bool hold_shown = limits.limit_shown_speed && timed && has_previous_ &&
                          max_rotation_speed > 0.0 && std::isfinite(max_rotation_speed);
  for (std::size_t j = 0; j < n; ++j) {
    const Quat input = rotations_ls[j];  // out may alias the input
    const Vec3 rotation_before = rotation_x_[j], translation_before = translation_x_[j];
    decay.apply(rotation_x_[j], rotation_v_[j]);
    decay.apply(translation_x_[j], translation_v_[j]);
    if (timed) {
      limit_speed(rotation_x_[j], rotation_v_[j], rotation_before, max_rotation_speed, dt_s);
      limit_speed(translation_x_[j], translation_v_[j], translation_before,
                  limits.max_translation_speed_mps, dt_s);
    }
    if (hold_shown) {
      limit_output_speed(rotation_x_[j], rotation_v_[j], rotation_before, input, previous_input_[j],
                         previous_output_[j], max_rotation_speed, dt_s,
                         j == 0 ? limits.root_catch_up_rad_s : 0.0);
    }
    rotations_out[j] = (exp_map(rotation_x_[j]) * input).normalized();
    translations_out[j] = translations_ls[j] + translation_x_[j];
    previous_input_[j] = input;
    previous_output_[j] = rotations_out[j];
  }
  has_previous_ = true;
}

double PoseInertializer::max_rotation_offset() const noexcept {
  double m = 0.0;
  for (const Vec3& x : rotation_x_) m = std::max(m, x.norm());
  return m;
}

double PoseInertializer::max_translation_offset() const noexcept {
  double m = 0.0;
  for (const Vec3& x : translation_x_) m = std::max(m, x.norm());
  return m;
}

}  // namespace duet
