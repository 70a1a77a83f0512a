// Temporal smoothing of the partner's pose (method.md 5.3): exponential smoothing of every joint
// in quaternion space, and inertialization at jumps (Holden's Motion-Matching spring.h /
// controller.cpp: record the offset at a transition, decay it every frame).
//
// Tunables are half-lives in seconds, not stiffnesses. A half-life <= 0 (or not finite) means
// "no smoothing": the output follows the input at once. Everything here is allocation-free after
// resize() and noexcept, so it runs on the per-frame path.
#pragma once

#include <limits>
#include <span>
#include <vector>

#include "duet/math/types.h"

namespace duet {

// Fraction of the remaining distance an exponential filter with this half-life covers in dt:
// 1 - 2^(-dt / half_life). 1 when half_life_s <= 0 or not finite; 0 when dt_s <= 0.
double half_life_alpha(double half_life_s, double dt_s) noexcept;

// One step of exponential smoothing of a rotation towards `target` (slerp along the shortest
// arc). For a target turning at a constant angular speed w, the output lags by at most
// w * half_life / ln 2 radians: a delay of at most half_life / ln 2 seconds (1.44 half-lives).
Quat smooth_rotation(const Quat& current, const Quat& target, double half_life_s,
                     double dt_s) noexcept;
Vec3 smooth_position(const Vec3& current, const Vec3& target, double half_life_s,
                     double dt_s) noexcept;

// Decays an offset x with velocity v towards zero like a critically damped spring
// (Holden's decay_spring_damper_exact, damping from the half-life as in his spring.h). Exact for
// any dt, so the result does not depend on the frame rate.
void decay_spring_damper(Vec3& x, Vec3& v, double half_life_s, double dt_s) noexcept;

// Per-joint exponential smoothing of a local pose (rotations in quaternion space, translations
// linearly). Causal: the output depends on past and present input only, with the delay bound of
// smooth_rotation(). The first frame after reset() passes through unchanged.
class PoseSmoother {
 public:
  PoseSmoother() = default;
  explicit PoseSmoother(int joint_count) { resize(joint_count); }
  void resize(int joint_count);  // allocates; also resets
  void reset() noexcept { primed_ = false; }
  int joint_count() const noexcept { return static_cast<int>(rotations_.size()); }

  // in/out spans have joint_count() elements; out may alias in.
  void apply(std::span<const Vec3> translations_ls, std::span<const Quat> rotations_ls,
             double rotation_half_life_s, double translation_half_life_s, double dt_s,
             std::span<Vec3> translations_out, std::span<Quat> rotations_out) noexcept;

 private:
  std::vector<Vec3> translations_;
  std::vector<Quat> rotations_;
  bool primed_ = false;
};

// Inertialization of a local pose at jumps. transition() records, per joint, the offset between
// the pose shown last (source) and the first pose after the jump (destination); update() decays
// the offsets with a critically damped spring and adds them to the current input, so the output
// never pops and converges to the input. Rotation offsets are applied on the left in the
// parent's frame (out = offset * in), as a rotation vector; translations additively.
//
// Offset velocities: Holden records off_v = (src_v + off_v) - dst_v. The velocity of the
// destination at the jump is unknown here (the input is one pose per frame), so we take
// dst_v = src_v: the velocity offset is carried over unchanged. The output stays continuous
// (C0), and its velocity right after the jump is that of the new input plus the decay.
class PoseInertializer {
 public:
  PoseInertializer() = default;
  explicit PoseInertializer(int joint_count) { resize(joint_count); }
  void resize(int joint_count);  // allocates; also resets
  void reset() noexcept;         // zero offsets
  int joint_count() const noexcept { return static_cast<int>(rotation_x_.size()); }

  // source: the pose shown last; destination: the new input. Spans have joint_count() elements.
  void transition(std::span<const Vec3> source_translations_ls,
                  std::span<const Quat> source_rotations_ls,
                  std::span<const Vec3> destination_translations_ls,
                  std::span<const Quat> destination_rotations_ls) noexcept;
  // How fast update() lets the offsets change.
  struct Limits {
    // No offset changes faster than these (each joint's rotation vector; each translation;
    // infinity or <= 0: no limit): a large offset (a jump to a far place) then crosses at that
    // speed and the short half-life only shapes its end, where a half-life long enough to keep
    // the whole decay under the speed leaves a long tail.
    double max_rotation_speed_rad_s = std::numeric_limits<double>::infinity();
    double max_translation_speed_mps = std::numeric_limits<double>::infinity();
    // With a finite max_rotation_speed_rad_s: each rotation offset also changes no faster than
    // keeps the joint shown turning, from the rotation shown last update, at most as fast as its
    // input turns or max_rotation_speed_rad_s, whichever is faster, so the blend never adds its
    // speed to a joint the input already turns fast. The offset is held, not dropped: it decays
    // once the input slows or turns the other way. A transition's cut is not counted as the
    // input turning.
    bool limit_shown_speed = false;
    // ... but the root (joint 0) may turn this much faster than its input: a facing held
    // through a whole spin would keep the body turned away for as long as the spin lasts.
    double root_catch_up_rad_s = 0.0;
  };
  // Decays the offsets by dt_s within `limits` and writes input + offset to out (out may alias
  // in).
  void update(std::span<const Vec3> translations_ls, std::span<const Quat> rotations_ls,
              double half_life_s, double dt_s, std::span<Vec3> translations_out,
              std::span<Quat> rotations_out, const Limits& limits) noexcept;
  void update(std::span<const Vec3> translations_ls, std::span<const Quat> rotations_ls,
              double half_life_s, double dt_s, std::span<Vec3> translations_out,
              std::span<Quat> rotations_out) noexcept {
    update(translations_ls, rotations_ls, half_life_s, dt_s, translations_out, rotations_out,
           Limits{});
  }

  // Largest remaining rotation offset over all joints, radians (0 after convergence).
  double max_rotation_offset() const noexcept;
  // Largest remaining translation offset over all joints, metres.
  double max_translation_offset() const noexcept;
  // The root's (joint 0) remaining translation offset, metres (0 with no joints).
  double root_translation_offset() const noexcept {
    return translation_x_.empty() ? 0.0 : translation_x_[0].norm();
  }

 private:
  std::vector<Vec3> rotation_x_;  // offset rotation vectors (log map)
  std::vector<Vec3> rotation_v_;  // their rates, rad/s
  std::vector<Vec3> translation_x_;
  std::vector<Vec3> translation_v_;
  std::vector<Quat> previous_input_;   // each joint's input rotation last update
  std::vector<Quat> previous_output_;  // and the rotation shown
  bool has_previous_ = false;
};

}  // namespace duet
