// Smoothing and inertialization: convergence, a bounded delay, continuity across jumps, no NaN.
#include "duet/partner/smoothing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "duet/math/rotation.h"

namespace duet {
namespace {

TEST(HalfLife, Alpha) {
  EXPECT_DOUBLE_EQ(half_life_alpha(0.1, 0.1), 0.5);
  EXPECT_DOUBLE_EQ(half_life_alpha(0.1, 0.2), 0.75);
  EXPECT_DOUBLE_EQ(half_life_alpha(0.0, 0.1), 1.0);  // no smoothing
  EXPECT_DOUBLE_EQ(half_life_alpha(-1.0, 0.1), 1.0);
  EXPECT_DOUBLE_EQ(half_life_alpha(NAN, 0.1), 1.0);
  EXPECT_DOUBLE_EQ(half_life_alpha(0.1, 0.0), 0.0);  // no time passed
  EXPECT_DOUBLE_EQ(half_life_alpha(0.1, NAN), 0.0);
}

TEST(SmoothRotation, ConvergesToAConstantTarget) {
  Quat q = Quat::Identity();
  const Quat target = quat_from_axis_angle(Vec3(1, 2, 3).normalized(), 2.5);
  const double h = 0.05, dt = 1.0 / 60;
  for (int i = 0; i < 60; ++i) q = smooth_rotation(q, target, h, dt);  // 1 s = 20 half-lives
  EXPECT_LT(q.angularDistance(target), 2.5 * std::exp2(-19.0));
  // After exactly one half-life (3 frames of 1/60 s at h = 0.05) half the angle is covered.
  Quat r = Quat::Identity();
  for (int i = 0; i < 3; ++i) r = smooth_rotation(r, target, h, dt);
  EXPECT_NEAR(r.angularDistance(target), 1.25, 1e-9);
}

TEST(SmoothRotation, DelayIsBoundedByHalfLifeOverLn2) {
  const Vec3 axis = Vec3(0.3, 1.0, -0.2).normalized();
  const double w = 4.0;  // rad/s
  for (const double h : {0.02, 0.05, 0.1}) {
    for (const double fps : {30.0, 60.0, 120.0}) {
      const double dt = 1.0 / fps;
      Quat q = Quat::Identity();
      double lag = 0.0;
      for (int i = 1; i <= static_cast<int>(3.0 * fps); ++i) {
        const Quat target = quat_from_axis_angle(axis, w * i * dt);
        q = smooth_rotation(q, target, h, dt);
        lag = q.angularDistance(target);
        ASSERT_LE(lag, w * h / std::log(2.0) + 1e-9) << "h " << h << " fps " << fps;
      }
      // Settled: the lag approaches the bound as dt -> 0 and is never negligible.
      EXPECT_GT(lag, 0.5 * w * h / std::log(2.0));
    }
  }
}

TEST(SmoothRotation, TakesTheShortestArcAndNeverMakesNaN) {
  const Quat q = quat_from_axis_angle(Vec3::UnitY(), 0.4);
  Quat minus_q = q;
  minus_q.coeffs() = -q.coeffs();  // the same rotation
  EXPECT_LT(smooth_rotation(q, minus_q, 0.05, 1.0 / 60).angularDistance(q), 1e-12);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  Quat s = Quat::Identity();
  for (int i = 0; i < 1000; ++i) {
    const Quat target = Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
    s = smooth_rotation(s, target, 0.03, (i % 7) / 60.0);
    ASSERT_TRUE(s.coeffs().allFinite());
    ASSERT_NEAR(s.norm(), 1.0, 1e-12);
  }
}

TEST(PoseSmoother, FirstFramePassesThroughThenSmooths) {
  PoseSmoother smoother(2);
  std::vector<Vec3> t = {Vec3(1, 2, 3), Vec3::Zero()};
  std::vector<Quat> r = {Quat::Identity(), quat_from_axis_angle(Vec3::UnitX(), 1.0)};
  std::vector<Vec3> to(2);
  std::vector<Quat> ro(2);
  smoother.apply(t, r, 0.1, 0.1, 1.0 / 60, to, ro);
  EXPECT_EQ(to[0], t[0]);
  EXPECT_TRUE(ro[1].isApprox(r[1]));
  t[0] = Vec3(2, 2, 3);
  r[1] = quat_from_axis_angle(Vec3::UnitX(), 2.0);
  smoother.apply(t, r, 0.1, 0.1, 0.1, to, ro);  // one half-life
  EXPECT_NEAR(to[0].x(), 1.5, 1e-12);
  EXPECT_NEAR(ro[1].angularDistance(r[1]), 0.5, 1e-9);
  // In place, and with no half-life it follows at once.
  smoother.apply(t, r, 0.0, 0.0, 0.1, t, r);
  EXPECT_NEAR(t[0].x(), 2.0, 1e-12);
  smoother.reset();
  t[0] = Vec3(9, 9, 9);
  smoother.apply(t, r, 1.0, 1.0, 0.1, to, ro);
  EXPECT_EQ(to[0], t[0]);
}

TEST(DecaySpringDamper, IsExactForAnyFrameRate) {
  Vec3 x30(1, -2, 0.5), v30(0.5, 0, 0), x120 = x30, v120 = v30;
  for (int i = 0; i < 30; ++i) decay_spring_damper(x30, v30, 0.1, 1.0 / 30);
  for (int i = 0; i < 120; ++i) decay_spring_damper(x120, v120, 0.1, 1.0 / 120);
  EXPECT_LT((x30 - x120).norm(), 1e-12);
  EXPECT_LT(x30.norm(), 1e-3);  // 10 half-lives
  Vec3 x(1, 1, 1), v = Vec3::Zero();
  decay_spring_damper(x, v, 0.0, 0.1);  // no half-life: gone at once
  EXPECT_EQ(x, Vec3::Zero());
}

// A joint animated at a constant angular speed jumps by `jump` radians at frame 30.
struct JumpRun {
  std::vector<double> output_steps;  // per-frame angular change of the output
  double final_error = 0.0;          // output vs input at the end
  double largest_input_step = 0.0;   // excluding the jump
  std::vector<double> translation_steps;
};

// The input turns at w rad/s until stop_s (then holds still).
struct InputTurn {
  double w = 1.5;
  double stop_s = std::numeric_limits<double>::infinity();
  bool limit_shown_speed = false;
  double catch_up_rad_s = 0.0;  // the joint is the root
};

JumpRun run_jump(double jump, double half_life, double fps, double seconds,
                 double max_rotation_speed = std::numeric_limits<double>::infinity(),
                 double max_translation_speed = std::numeric_limits<double>::infinity(),
                 const InputTurn& turn = {}) {
  PoseInertializer inertializer(1);
  const Vec3 axis = Vec3(0.2, 1.0, 0.1).normalized();
  const double w = turn.w;  // rad/s
  const double dt = 1.0 / fps;
  std::vector<Vec3> t(1, Vec3::Zero()), t_out(1);
  std::vector<Quat> r(1), r_out(1);
  Quat previous_out = Quat::Identity();
  Vec3 previous_t = Vec3::Zero();
  JumpRun run;
  const int frames = static_cast<int>(seconds * fps);
  for (int i = 0; i < frames; ++i) {
    const bool jumped = i == 30;
    const double angle = w * std::min(i * dt, turn.stop_s) + (i >= 30 ? jump : 0.0);
    r[0] = quat_from_axis_angle(axis, angle);
    t[0] = Vec3(i >= 30 ? 0.5 : 0.0, 0, 0);
    if (jumped)
      inertializer.transition(std::vector<Vec3>{previous_t}, std::vector<Quat>{previous_out}, t, r);
    inertializer.update(t, r, half_life, dt, t_out, r_out,
                        {.max_rotation_speed_rad_s = max_rotation_speed,
                         .max_translation_speed_mps = max_translation_speed,
                         .limit_shown_speed = turn.limit_shown_speed,
                         .root_catch_up_rad_s = turn.catch_up_rad_s});
    if (i > 0) run.output_steps.push_back(r_out[0].angularDistance(previous_out));
    if (i > 0) run.translation_steps.push_back((t_out[0] - previous_t).norm());
    if (i > 0 && !jumped && i * dt <= turn.stop_s) {
      run.largest_input_step = std::max(run.largest_input_step, w * dt);
    }
    previous_out = r_out[0];
    previous_t = t_out[0];
  }
  run.final_error = r_out[0].angularDistance(r[0]) + (t_out[0] - t[0]).norm();
  return run;
}

TEST(PoseInertializer, OutputIsContinuousAcrossAJumpAndConverges) {
  for (const double fps : {30.0, 60.0, 120.0}) {
    const double h = 0.1;
    const JumpRun run = run_jump(1.2, h, fps, 3.0);
    // Without blending the output would turn by 1.2 rad in one frame. With it, each frame turns
    // by at most the input's own step plus the decay's peak rate (critically damped from rest:
    // x0 * y / e with y = 2 ln 2 / h) over one frame.
    // The recorded offset is the jump plus the input's motion over the jump frame.
    const double x0 = 1.2 + 1.5 / fps;
    const double peak_rate = x0 * (2.0 * std::log(2.0) / h) / std::exp(1.0);
    for (const double step : run.output_steps) {
      ASSERT_LE(step, run.largest_input_step + peak_rate / fps + 1e-9) << "fps " << fps;
    }
    EXPECT_LT(*std::max_element(run.output_steps.begin(), run.output_steps.end()), 0.25 * 1.2);
    EXPECT_LT(run.final_error, 1e-6);  // 2 s after the jump = 20 half-lives
  }
}

TEST(PoseInertializer, SpeedLimitsHoldTheOffsetsAndTheyStillArrive) {
  // A 2 rad turn and a 0.5 m move at a jump, each offset held to 4 rad/s and 3 m/s: no frame
  // turns faster than the input plus the cap, and the short half-life brings it home soon after
  // the cap's own crossing time (0.5 s for 2 rad), where a half-life stretched to keep the
  // decay under 4 rad/s (2 * 2 ln 2 / (e * 4) = 0.26 s) is still 6 cm / 0.1 rad away.
  for (const double fps : {30.0, 60.0, 120.0}) {
    const JumpRun run = run_jump(2.0, 0.1, fps, 3.0, 4.0, 3.0);
    for (const double step : run.output_steps) {
      ASSERT_LE(step, run.largest_input_step + 4.0 / fps + 1e-9) << "fps " << fps;
    }
    for (const double step : run.translation_steps) ASSERT_LE(step, 3.0 / fps + 1e-9);
    EXPECT_LT(run.final_error, 1e-6);
    // 0.9 s after the jump (frame 30): within 0.02 rad.
    const JumpRun short_run = run_jump(2.0, 0.1, fps, 30.0 / fps + 0.9, 4.0, 3.0);
    EXPECT_LT(short_run.final_error, 0.02) << "fps " << fps;
  }
}

TEST(PoseInertializer, TheShownJointTurnsNoFasterThanItsInputOrTheCap) {
  // The output has to catch up 1.5 rad with the input turning the same way. The cap alone lets
  // the offset's 4 rad/s add to the input's: up to 6 rad/s shown for a 2 rad/s input. Limited,
  // no frame turns faster than max(input, cap), and it still arrives.
  for (const double fps : {30.0, 60.0, 120.0}) {
    const double largest_capped = [&] {
      const JumpRun run = run_jump(1.5, 0.1, fps, 3.0, 4.0, 3.0, {.w = 2.0});
      return *std::max_element(run.output_steps.begin(), run.output_steps.end());
    }();
    EXPECT_GT(largest_capped, 5.0 / fps) << "fps " << fps;  // the test would catch the sum
    const JumpRun run =
        run_jump(1.5, 0.1, fps, 3.0, 4.0, 3.0, {.w = 2.0, .limit_shown_speed = true});
    for (const double step : run.output_steps) ASSERT_LE(step, 4.0 / fps + 1e-9) << "fps " << fps;
    EXPECT_LT(run.final_error, 1e-6) << "fps " << fps;
  }
}

TEST(PoseInertializer, AnOffsetHeldBehindAFastInputArrivesOnceItSlows) {
  // The input turns at 5 rad/s, faster than the 4 rad/s cap, for 1.5 s: the shown joint turns
  // no faster than it (the offset waits), then the input stops and the offset decays home.
  for (const double fps : {30.0, 60.0, 120.0}) {
    const JumpRun run = run_jump(1.0, 0.1, fps, 3.0, 4.0, 3.0,
                                 {.w = 5.0, .stop_s = 1.5, .limit_shown_speed = true});
    for (const double step : run.output_steps) ASSERT_LE(step, 5.0 / fps + 1e-9) << "fps " << fps;
    EXPECT_LT(run.final_error, 1e-6) << "fps " << fps;
  }
}

TEST(PoseInertializer, TheRootCatchesUpThroughASpin) {
  // The root turns at 8 rad/s for 2 s after a jump that left it 1 rad behind. Held, it stays
  // 1 rad behind for the whole spin; with 2 rad/s to catch up it arrives within 1 s, and no
  // frame turns faster than the input plus that.
  for (const double fps : {30.0, 60.0, 120.0}) {
    const double spin_end_s = 30.0 / fps + 2.0;
    const JumpRun held = run_jump(1.0, 0.1, fps, 30.0 / fps + 1.0, 6.0, 3.0,
                                  {.w = 8.0, .stop_s = spin_end_s, .limit_shown_speed = true});
    EXPECT_GT(held.final_error, 0.9) << "fps " << fps;
    const JumpRun run = run_jump(
        1.0, 0.1, fps, 30.0 / fps + 1.0, 6.0, 3.0,
        {.w = 8.0, .stop_s = spin_end_s, .limit_shown_speed = true, .catch_up_rad_s = 2.0});
    for (const double step : run.output_steps) {
      ASSERT_LE(step, 10.0 / fps + 1e-9) << "fps " << fps;
    }
    EXPECT_LT(run.final_error, 0.01) << "fps " << fps;
  }
}

TEST(PoseInertializer, RepeatedJumpsStayBoundedAndFinite) {
  PoseInertializer inertializer(3);
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Vec3> t(3), shown_t(3, Vec3::Zero());
  std::vector<Quat> r(3), shown_r(3, Quat::Identity());
  for (int i = 0; i < 2000; ++i) {
    for (int j = 0; j < 3; ++j) {
      r[static_cast<std::size_t>(j)] = Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
      t[static_cast<std::size_t>(j)] = Vec3(n(rng), n(rng), n(rng));
    }
    inertializer.transition(shown_t, shown_r, t, r);  // a jump every frame
    inertializer.update(t, r, 0.1, 1.0 / 60, shown_t, shown_r,
                        {.max_rotation_speed_rad_s = 6.0,
                         .max_translation_speed_mps = 4.0,
                         .limit_shown_speed = i % 2 == 0,
                         .root_catch_up_rad_s = 2.0});
    for (int j = 0; j < 3; ++j) {
      ASSERT_TRUE(shown_r[static_cast<std::size_t>(j)].coeffs().allFinite());
      ASSERT_TRUE(shown_t[static_cast<std::size_t>(j)].allFinite());
    }
    ASSERT_LE(inertializer.max_rotation_offset(), 2.0 * kPi);
  }
  inertializer.reset();
  EXPECT_EQ(inertializer.max_rotation_offset(), 0.0);
  EXPECT_EQ(inertializer.max_translation_offset(), 0.0);
}

}  // namespace
}  // namespace duet
