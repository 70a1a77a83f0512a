#include "duet/eval/performance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "duet/eval/runner.h"
#include "duet/features/feature_extractor.h"
#include "duet/io/motion_file.h"
#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"
#include "duet/motion/rig_variants.h"
#include "duet/motion/up_axis.h"
#include "features/synthetic_dancer.h"

namespace duet {
namespace {

using testing::daz_roles;
using testing::make_dance;
using testing::make_role_skeleton;

struct Fixture {
  Clip clip;
  JointRoles roles;
  SourceTake source() const { return {3, &clip, roles}; }
};

Fixture make_fixture(int frames = 900) {
  auto skeleton = make_role_skeleton();
  Fixture f{make_dance(skeleton, 60.0, frames), daz_roles(*skeleton)};
  return f;
}

// The pose of `clip` at a real template frame (what the truth says frame k shows).
Pose pose_at_frame(const Clip& clip, double template_frame) {
  Pose pose;
  clip.sample(template_frame / clip.frame_rate(), pose);
  return pose;
}

// Frame k of the performance equals the take's pose at the true template frame, up to a rigid
// turn about the vertical and a horizontal move of the root. Returns that move.
struct RigidMove {
  double yaw;
  Vec3 offset;
};
RigidMove expect_same_pose_up_to_rigid(const Performance& p, const Clip& take, int k) {
  const TruthFrame& truth = p.truth[static_cast<std::size_t>(k)];
  const Pose expected = pose_at_frame(take, truth.template_frame);
  const auto translations = p.motion.translations_ls(k);
  const auto rotations = p.motion.rotations_ls(k);
  for (int j = 1; j < take.joint_count(); ++j) {
    const auto i = static_cast<std::size_t>(j);
    EXPECT_TRUE(translations[i].isApprox(expected.translations_ls[i], 1e-9)) << "frame " << k;
    EXPECT_LT(rotations[i].angularDistance(expected.rotations_ls[i]), 1e-9) << "frame " << k;
  }
  const double yaw = wrap_angle(heading_yaw(rotations[0]) - heading_yaw(expected.rotations_ls[0]));
  EXPECT_LT(rotations[0].angularDistance(yaw_rotation(yaw) * expected.rotations_ls[0]), 1e-9)
      << "frame " << k;
  const Vec3 offset = translations[0] - yaw_rotation(yaw) * expected.translations_ls[0];
  EXPECT_NEAR(offset.y(), 0.0, 1e-9) << "frame " << k;
  return {yaw, offset};
}

TEST(Play, SteadyTempoOneIsTheTakeItself) {
  const Fixture f = make_fixture();
  const Performance p = play(f.source(), {});
  ASSERT_EQ(p.frame_count(), f.clip.frame_count());
  EXPECT_DOUBLE_EQ(p.template_rate_hz, 60.0);
  for (int k = 0; k < p.frame_count(); k += 37) {
    const TruthFrame& t = p.truth[static_cast<std::size_t>(k)];
    EXPECT_EQ(t.take, 3);
    EXPECT_NEAR(t.template_frame, k, 1e-6);
    EXPECT_FALSE(t.in_pause || t.jump);
    EXPECT_DOUBLE_EQ(p.times_s[static_cast<std::size_t>(k)], k / 60.0);
    EXPECT_TRUE(p.motion.translations_ls(k)[0].isApprox(f.clip.translations_ls(k)[0], 1e-9));
  }
}

TEST(Play, FastTempoAtThirtyHertzSamplesTheTakeAtTheTrueFrame) {
  const Fixture f = make_fixture();
  PlayOptions options;
  options.tempo.factor = 1.4;
  options.rate_hz = 30.0;
  const Performance p = play(f.source(), options);
  EXPECT_DOUBLE_EQ(p.motion.frame_rate(), 30.0);
  // 899 template frames / 60 fps / 1.4 * 30 Hz + the first frame.
  EXPECT_NEAR(p.frame_count(), 899.0 / 60.0 / 1.4 * 30.0 + 1.0, 1.0);
  for (int k = 0; k < p.frame_count(); ++k) {
    EXPECT_NEAR(p.truth[static_cast<std::size_t>(k)].template_frame, k * 1.4 * 2.0, 1e-6);
    const RigidMove m = expect_same_pose_up_to_rigid(p, f.clip, k);
    EXPECT_NEAR(m.yaw, 0.0, 1e-9);
    EXPECT_LT(m.offset.norm(), 1e-9);
  }
}

TEST(Play, DriftingTempoStaysWithinItsBounds) {
  const Fixture f = make_fixture(1800);
  PlayOptions options;
  options.tempo.drift_low = 0.8;
  options.tempo.drift_high = 1.3;
  options.tempo.drift_period_s = 6.0;
  const Performance p = play(f.source(), options);
  double slowest = 10.0, fastest = 0.0;
  for (std::size_t k = 1; k < p.truth.size(); ++k) {
    const double rate = p.truth[k].template_frame - p.truth[k - 1].template_frame;  // per 1/60 s
    slowest = std::min(slowest, rate);
    fastest = std::max(fastest, rate);
  }
  EXPECT_GT(slowest, 0.8 - 1e-3);
  EXPECT_LT(fastest, 1.3 + 1e-3);
  EXPECT_LT(slowest, 0.85);  // it does reach both ends over several periods
  EXPECT_GT(fastest, 1.25);
}

ImproviseOptions improv_options(double pause_prob) {
  ImproviseOptions options;
  options.duration_s = 40.0;
  options.pause_prob = pause_prob;
  options.seed = 7;
  return options;
}

// Largest horizontal root step and heading change per frame in the take itself.
void take_steps(const Clip& clip, double& max_step, double& max_turn) {
  max_step = max_turn = 0.0;
  for (int f = 1; f < clip.frame_count(); ++f) {
    Vec3 d = clip.translations_ls(f)[0] - clip.translations_ls(f - 1)[0];
    d.y() = 0.0;
    max_step = std::max(max_step, d.norm());
    max_turn = std::max(max_turn, std::abs(wrap_angle(heading_yaw(clip.rotations_ls(f)[0]) -
                                                      heading_yaw(clip.rotations_ls(f - 1)[0]))));
  }
}

class Improvise : public ::testing::TestWithParam<double> {};

TEST_P(Improvise, GroundTruthMatchesThePosesAndTheRootPathIsContinuous) {
  const Fixture f = make_fixture(1800);
  const SourceTake source = f.source();
  Result<Performance> made = improvise(std::span(&source, 1), improv_options(GetParam()));
  ASSERT_TRUE(made) << made.error().message;
  const Performance& p = made.value();
  EXPECT_EQ(p.frame_count(), 40 * 60);

  double max_step = 0.0, max_turn = 0.0;
  take_steps(f.clip, max_step, max_turn);
  int jumps = 0, pause_frames = 0;
  std::optional<RigidMove> segment_move;
  for (int k = 0; k < p.frame_count(); ++k) {
    const TruthFrame& t = p.truth[static_cast<std::size_t>(k)];
    EXPECT_EQ(t.take, 3);
    EXPECT_GE(t.template_frame, 0.0);
    EXPECT_LE(t.template_frame, f.clip.frame_count() - 1.0);
    jumps += t.jump ? 1 : 0;
    pause_frames += t.in_pause ? 1 : 0;
    if (t.jump) segment_move.reset();
    if (!t.in_pause) {
      // Same pose as the take at the true frame, one rigid move per segment.
      const RigidMove m = expect_same_pose_up_to_rigid(p, f.clip, k);
      if (segment_move) {
        EXPECT_NEAR(wrap_angle(m.yaw - segment_move->yaw), 0.0, 1e-9) << "frame " << k;
        EXPECT_TRUE(m.offset.isApprox(segment_move->offset, 1e-9)) << "frame " << k;
      }
      segment_move = m;
    } else {
      segment_move.reset();
    }
    if (k == 0) continue;
    // No teleport: root steps and turns no larger than the take's own (plus the tiny sway).
    Vec3 step = p.motion.translations_ls(k)[0] - p.motion.translations_ls(k - 1)[0];
    step.y() = 0.0;
    EXPECT_LE(step.norm(), 1.05 * max_step + 0.002) << "frame " << k << (t.jump ? " (jump)" : "");
    const double turn = std::abs(wrap_angle(heading_yaw(p.motion.rotations_ls(k)[0]) -
                                            heading_yaw(p.motion.rotations_ls(k - 1)[0])));
    EXPECT_LE(turn, 1.05 * max_turn + 0.002) << "frame " << k;
  }
  EXPECT_GE(jumps, 40 / 6);  // segments are 2-5 s and most of them end in a jump
  if (GetParam() > 0.0) {
    // Every jump is preceded by a 0.3-0.8 s hold.
    EXPECT_GE(pause_frames, jumps * 0.3 * 60 - 1);
    EXPECT_LE(pause_frames, jumps * 0.8 * 60 + jumps);
    for (int k = 1; k < p.frame_count(); ++k) {
      if (p.truth[static_cast<std::size_t>(k)].jump) {
        EXPECT_TRUE(p.truth[static_cast<std::size_t>(k - 1)].in_pause) << "frame " << k;
      }
    }
  } else {
    EXPECT_EQ(pause_frames, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(WithAndWithoutPause, Improvise, ::testing::Values(0.0, 1.0));

TEST(Improvise, ReplaysSegmentsOutOfOrderWithRepeatsAndSkips) {
  const Fixture f = make_fixture(1800);
  const SourceTake source = f.source();
  Result<Performance> made = improvise(std::span(&source, 1), improv_options(0.0));
  ASSERT_TRUE(made);
  int backwards = 0, forwards = 0;
  for (std::size_t k = 1; k < made.value().truth.size(); ++k) {
    const TruthFrame& t = made.value().truth[k];
    if (!t.jump) {
      const double d = t.template_frame - made.value().truth[k - 1].template_frame;
      EXPECT_NEAR(d, 1.0, 1e-6) << "frame " << k;  // tempo 1 between jumps
      continue;
    }
    const double d = t.template_frame - made.value().truth[k - 1].template_frame;
    backwards += d < 0.0 ? 1 : 0;
    forwards += d > 2.0 ? 1 : 0;
  }
  EXPECT_GT(backwards, 0);
  EXPECT_GT(forwards, 0);
}

TEST(Improvise, IsAPureFunctionOfTheSeed) {
  const Fixture f = make_fixture();
  const SourceTake source = f.source();
  ImproviseOptions options = improv_options(0.5);
  const Performance a = improvise(std::span(&source, 1), options).value();
  const Performance b = improvise(std::span(&source, 1), options).value();
  options.seed = 8;
  const Performance c = improvise(std::span(&source, 1), options).value();
  ASSERT_EQ(a.frame_count(), b.frame_count());
  bool differs = false;
  for (std::size_t k = 0; k < a.truth.size(); ++k) {
    EXPECT_EQ(a.truth[k].template_frame, b.truth[k].template_frame);
    if (k < c.truth.size() && a.truth[k].template_frame != c.truth[k].template_frame) {
      differs = true;
    }
  }
  EXPECT_TRUE(differs);
}

TEST(Improvise, DrawsFromSeveralTakesAndRejectsBadInput) {
  const Fixture f = make_fixture(900);
  auto skeleton = make_role_skeleton();
  const Clip other = make_dance(skeleton, 60.0, 700);
  const std::vector<SourceTake> sources = {f.source(), {5, &other, f.roles}};
  ImproviseOptions options = improv_options(0.0);
  options.duration_s = 120.0;
  Result<Performance> made = improvise(sources, options);
  ASSERT_TRUE(made);
  bool saw[2] = {false, false};
  for (const TruthFrame& t : made.value().truth) {
    ASSERT_TRUE(t.take == 3 || t.take == 5);
    saw[t.take == 5 ? 1 : 0] = true;
    EXPECT_LE(t.template_frame, (t.take == 3 ? 899.0 : 699.0) + 1e-9);
  }
  EXPECT_TRUE(saw[0] && saw[1]);

  EXPECT_FALSE(improvise({}, options));
  const Clip slow = make_dance(skeleton, 30.0, 700);
  const std::vector<SourceTake> mixed = {f.source(), {5, &slow, f.roles}};
  Result<Performance> bad = improvise(mixed, options);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("frame rates"), std::string::npos);
}

TEST(Perturbations, SensorNoiseHasTheRequestedSizeAndKeepsTheTruth) {
  const Fixture f = make_fixture(600);
  const Performance clean = play(f.source(), {});
  const Performance noisy = with_sensor_noise(clean, {3.0, 0.01, 11});
  double angle_sq = 0.0, position_sq = 0.0;
  long long n = 0;
  for (int k = 0; k < clean.frame_count(); ++k) {
    for (int j = 0; j < clean.motion.joint_count(); ++j) {
      const auto i = static_cast<std::size_t>(j);
      if (clean.motion.skeleton().joints[i].end_site) continue;
      const double a =
          clean.motion.rotations_ls(k)[i].angularDistance(noisy.motion.rotations_ls(k)[i]);
      angle_sq += a * a;
      ++n;
      if (j > 0) {
        EXPECT_EQ(clean.motion.translations_ls(k)[i], noisy.motion.translations_ls(k)[i]);
      }
    }
    position_sq +=
        (clean.motion.translations_ls(k)[0] - noisy.motion.translations_ls(k)[0]).squaredNorm();
  }
  EXPECT_NEAR(rad_to_deg(std::sqrt(angle_sq / static_cast<double>(n))), 3.0, 0.15);
  EXPECT_NEAR(std::sqrt(position_sq / clean.frame_count() / 3.0), 0.01, 0.001);
  for (std::size_t k = 0; k < clean.truth.size(); ++k) {
    EXPECT_EQ(clean.truth[k].template_frame, noisy.truth[k].template_frame);
  }
}

TEST(Perturbations, SensorNoiseMovesTheRootOnlyWhenEveryJointHasPositionChannels) {
  // Rigs like the Bandai one animate every joint's offset; those are bone lengths, not sensor
  // positions, and must keep their lengths under the sensor's noise.
  const Fixture f = make_fixture(120);
  const Performance clean = play(f.source(), {});
  auto all_positions = std::make_shared<Skeleton>(clean.motion.skeleton());
  for (Joint& joint : all_positions->joints) {
    if (!joint.end_site && !joint.has_position_channels()) {
      joint.channels.insert(joint.channels.begin(),
                            {Channel::kXposition, Channel::kYposition, Channel::kZposition});
    }
  }
  Performance on_rig = clean;
  on_rig.motion = Clip(all_positions, clean.motion.frame_rate(), clean.frame_count());
  for (int k = 0; k < clean.frame_count(); ++k) {
    std::ranges::copy(clean.motion.translations_ls(k), on_rig.motion.translations_ls(k).begin());
    std::ranges::copy(clean.motion.rotations_ls(k), on_rig.motion.rotations_ls(k).begin());
  }
  const Performance noisy = with_sensor_noise(on_rig, {0.0, 0.01, 5});
  double root_moved = 0.0;
  for (int k = 0; k < clean.frame_count(); ++k) {
    root_moved += (noisy.motion.translations_ls(k)[0] - on_rig.motion.translations_ls(k)[0]).norm();
    for (int j = 1; j < clean.motion.joint_count(); ++j) {
      const auto i = static_cast<std::size_t>(j);
      EXPECT_EQ(noisy.motion.translations_ls(k)[i], on_rig.motion.translations_ls(k)[i]) << j;
    }
  }
  EXPECT_GT(root_moved / clean.frame_count(), 0.005);
}

// The sensor's white noise on `clean` (seen on the root's position, which nothing else moves)
// is the same with and without what `add` puts in the options (a suit's slow errors,
// occlusions): each draws from its own random stream.
template <typename Add>
void expect_white_noise_unchanged(const Performance& clean, Add add) {
  const SensorNoiseOptions white{3.0, 0.01, 11};
  SensorNoiseOptions white_and_more = white;
  add(white_and_more);
  const Performance a = with_sensor_noise(clean, white);
  const Performance b = with_sensor_noise(clean, white_and_more);
  for (int k = 0; k < clean.frame_count(); ++k) {
    ASSERT_EQ(a.motion.translations_ls(k)[0], b.motion.translations_ls(k)[0]) << "frame " << k;
  }
}

TEST(Perturbations, ASuitsCalibrationIsConstantAndItsDriftWandersSlowly) {
  // Bias alone: every frame of a joint is off by the same rotation, of the requested RMS size over
  // the joints. Drift alone: the error moves, slowly (10 s), and has the requested RMS size.
  const Fixture f = make_fixture(1800);
  const Performance clean = play(f.source(), {});
  SensorNoiseOptions bias_only;
  bias_only.bias_deg = 5.0;
  bias_only.seed = 3;
  SensorNoiseOptions drift_only;
  drift_only.drift_deg = 5.0;
  drift_only.drift_time_s = 2.0;  // 30 s of take: 15 time constants, so the RMS settles
  drift_only.seed = 3;
  const Performance biased = with_sensor_noise(clean, bias_only);
  const Performance drifting = with_sensor_noise(clean, drift_only);
  // The error of joint i at frame k as a rotation vector (clean^-1 * noisy).
  auto error = [&](const Performance& p, int k, std::size_t i) {
    return log_map(clean.motion.rotations_ls(k)[i].conjugate() * p.motion.rotations_ls(k)[i]);
  };
  double bias_sq = 0.0, drift_sq = 0.0, drift_step_sq = 0.0;
  long long n = 0, steps = 0;
  for (int j = 0; j < clean.motion.joint_count(); ++j) {
    const auto i = static_cast<std::size_t>(j);
    if (clean.motion.skeleton().joints[i].end_site) continue;
    const Vec3 first = error(biased, 0, i);
    for (int k = 0; k < clean.frame_count(); ++k) {
      EXPECT_LT((error(biased, k, i) - first).norm(), 1e-9) << "joint " << j << " frame " << k;
      bias_sq += first.squaredNorm();
      drift_sq += error(drifting, k, i).squaredNorm();
      ++n;
      if (k > 0) {
        drift_step_sq += (error(drifting, k, i) - error(drifting, k - 1, i)).squaredNorm();
        ++steps;
      }
    }
  }
  const double bias_rms = rad_to_deg(std::sqrt(bias_sq / static_cast<double>(n)));
  const double drift_rms = rad_to_deg(std::sqrt(drift_sq / static_cast<double>(n)));
  const double drift_step_rms = rad_to_deg(std::sqrt(drift_step_sq / static_cast<double>(steps)));
  EXPECT_NEAR(bias_rms, 5.0, 1.5);  // over a handful of joints
  EXPECT_GT(bias_rms, 0.5);
  EXPECT_NEAR(drift_rms, 5.0, 1.5);
  // An Ornstein-Uhlenbeck step over dt has RMS sigma sqrt(1 - exp(-2 dt / tau)): 0.64 degrees at
  // 60 Hz and tau 2 s. White noise of the same size would step by sqrt(2) x 5 = 7 degrees.
  EXPECT_NEAR(drift_step_rms, 5.0 * std::sqrt(1.0 - std::exp(-2.0 / 60.0 / 2.0)), 0.1);
  for (std::size_t k = 0; k < clean.truth.size(); ++k) {
    EXPECT_EQ(clean.truth[k].template_frame, drifting.truth[k].template_frame);
  }
  // Without slow errors the white noise is what it was: the slow errors have their own stream.
  expect_white_noise_unchanged(clean, [](SensorNoiseOptions& o) { o.bias_deg = 2.0; });
}

TEST(Perturbations, AnOccludedArmIsHeldWhereLastSeenWhileTheBodyMovesOn) {
  const Fixture f = make_fixture(1800);
  const Performance clean = play(f.source(), {});
  SensorNoiseOptions options;
  options.occlusion_every_s = 4.0;  // 30 s of take: about 7 spans of 0.3-1.5 s
  options.seed = 5;
  const Performance occluded = with_sensor_noise(clean, options);
  const std::array<std::array<Role, 3>, 2> arms = {
      {{Role::kLeftShoulder, Role::kLeftElbow, Role::kLeftWrist},
       {Role::kRightShoulder, Role::kRightElbow, Role::kRightWrist}}};
  const auto same = [](const Quat& a, const Quat& b) { return a.angularDistance(b) < 1e-12; };
  int held_frames = 0, spans = 0;
  std::array<int, 2> spans_of_arm{};
  int previous_arm = -1;
  for (int k = 0; k < clean.frame_count(); ++k) {
    // Which arm (if any) differs from the clean take at frame k.
    int arm = -1;
    for (int a = 0; a < 2; ++a) {
      for (const Role role : arms[static_cast<std::size_t>(a)]) {
        const auto i = static_cast<std::size_t>(f.roles[role]);
        if (!same(occluded.motion.rotations_ls(k)[i], clean.motion.rotations_ls(k)[i])) arm = a;
      }
    }
    // Every other joint, and the root's place, is the clean take's.
    for (int j = 0; j < clean.motion.joint_count(); ++j) {
      const auto i = static_cast<std::size_t>(j);
      const bool in_arm = arm >= 0 && std::ranges::any_of(arms[static_cast<std::size_t>(arm)],
                                                          [&](Role r) { return f.roles[r] == j; });
      if (!in_arm) {
        ASSERT_TRUE(same(occluded.motion.rotations_ls(k)[i], clean.motion.rotations_ls(k)[i]))
            << "joint " << j << " frame " << k;
      }
    }
    EXPECT_EQ(occluded.motion.translations_ls(k)[0], clean.motion.translations_ls(k)[0]);
    if (arm >= 0) {
      ASSERT_GT(k, 0) << "the first frame is never occluded";
      // The held arm shows the previous frame's rotations: still while the take moves it.
      for (const Role role : arms[static_cast<std::size_t>(arm)]) {
        const auto i = static_cast<std::size_t>(f.roles[role]);
        EXPECT_TRUE(
            same(occluded.motion.rotations_ls(k)[i], occluded.motion.rotations_ls(k - 1)[i]))
            << "frame " << k;
      }
      ++held_frames;
      if (previous_arm != arm) {
        ++spans;
        ++spans_of_arm[static_cast<std::size_t>(arm)];
      }
    }
    previous_arm = arm;
  }
  // About 7 spans of 0.9 s on average: 6 % to 40 % of the frames, both arms.
  EXPECT_GE(spans, 3);
  EXPECT_GT(held_frames, clean.frame_count() / 16);
  EXPECT_LT(held_frames, clean.frame_count() * 2 / 5);
  EXPECT_GT(spans_of_arm[0], 0);
  EXPECT_GT(spans_of_arm[1], 0);
  // The white noise is what it was without occlusions: the occlusions have their own stream.
  expect_white_noise_unchanged(clean, [](SensorNoiseOptions& o) { o.occlusion_every_s = 4.0; });
}

TEST(Perturbations, AGlitchTurnsOneJointGrosslyForAFewFrames) {
  const Fixture f = make_fixture(1800);
  const Performance clean = play(f.source(), {});
  SensorNoiseOptions options;
  options.glitch_every_s = 1.0;  // 30 s of take: about 30 pops of 0.01-0.05 s
  options.seed = 5;
  const Performance popped = with_sensor_noise(clean, options);
  int popped_frames = 0, pops = 0, run = 0, longest_run = 0;
  for (int k = 0; k < clean.frame_count(); ++k) {
    int turned = 0;
    double angle_deg = 0.0;
    for (int j = 0; j < clean.motion.joint_count(); ++j) {
      const auto i = static_cast<std::size_t>(j);
      const double d =
          popped.motion.rotations_ls(k)[i].angularDistance(clean.motion.rotations_ls(k)[i]);
      if (d > 1e-12) {
        ++turned;
        angle_deg = rad_to_deg(d);
        EXPECT_NE(j, 0) << "the root never pops";
      }
      EXPECT_EQ(popped.motion.translations_ls(k)[i], clean.motion.translations_ls(k)[i]);
    }
    // One joint at a time, turned by 30 to 90 degrees.
    ASSERT_LE(turned, 1) << "frame " << k;
    if (turned == 1) {
      EXPECT_GE(angle_deg, 30.0 - 1e-6) << "frame " << k;
      EXPECT_LE(angle_deg, 90.0 + 1e-6) << "frame " << k;
      ++popped_frames;
      pops += run == 0 ? 1 : 0;
      longest_run = std::max(longest_run, ++run);
    } else {
      run = 0;
    }
  }
  // Spans of at most 0.05 s: 3 frames at 60 Hz, or 4 where a span starts between two frames.
  EXPECT_GE(pops, 15);
  EXPECT_LE(longest_run, 4);
  EXPECT_LT(popped_frames, clean.frame_count() / 10);
  // The white noise is what it was without glitches: the glitches have their own stream.
  expect_white_noise_unchanged(clean, [](SensorNoiseOptions& o) { o.glitch_every_s = 1.0; });
}

TEST(Perturbations, AControllersGlitchReportsOneHandElsewhereForAFewFrames) {
  const Fixture f = make_fixture(1800);
  Performance clean = play(f.source(), {});
  clean.roles = f.roles;
  PointNoiseOptions quiet;
  quiet.position_m = 0.0;
  quiet.rotation_deg = 0.0;
  PointNoiseOptions glitching = quiet;
  glitching.glitch_every_s = 1.0;
  const Result<Performance> points_made = with_head_hands(clean, quiet);
  const Result<Performance> popped_made = with_head_hands(clean, glitching);
  ASSERT_TRUE(points_made && popped_made);
  const Performance* points = &points_made.value();
  const Performance* popped = &popped_made.value();
  int popped_frames = 0;
  for (int k = 0; k < points->frame_count(); ++k) {
    const auto head = static_cast<std::size_t>(kPointsHead);
    EXPECT_EQ(popped->motion.translations_ls(k)[head], points->motion.translations_ls(k)[head]);
    int moved = 0;
    for (const int hand : {kPointsLeftHand, kPointsRightHand}) {
      const auto i = static_cast<std::size_t>(hand);
      const double off =
          (popped->motion.translations_ls(k)[i] - points->motion.translations_ls(k)[i]).norm();
      if (off > 1e-12) {
        ++moved;
        EXPECT_GE(off, 0.1 - 1e-9) << "frame " << k;
        EXPECT_LE(off, 0.4 + 1e-9) << "frame " << k;
      }
    }
    ASSERT_LE(moved, 1) << "frame " << k;
    popped_frames += moved;
  }
  EXPECT_GT(popped_frames, 15);
  EXPECT_LT(popped_frames, points->frame_count() / 10);
}

// Frames flagged as the start of a jump in a performance's truth.
int count_jumps(const Performance& performance) {
  return static_cast<int>(
      std::ranges::count_if(performance.truth, [](const TruthFrame& t) { return t.jump; }));
}

TEST(Perturbations, FrameLossDropsInBurstsAndDelaysTimestamps) {
  const Fixture f = make_fixture(1800);
  const SourceTake source = f.source();
  const Performance full = improvise(std::span(&source, 1), improv_options(0.0)).value();
  const Performance lossy = with_frame_loss(full, {0.10, 0.20, 1.5, 0.002, 3});
  const double kept = static_cast<double>(lossy.frame_count()) / full.frame_count();
  EXPECT_NEAR(kept, 0.90, 0.03);
  EXPECT_EQ(count_jumps(full), count_jumps(lossy));  // a dropped jump frame passes its flag on
  for (int k = 1; k < lossy.frame_count(); ++k) {
    EXPECT_GT(lossy.times_s[static_cast<std::size_t>(k)],
              lossy.times_s[static_cast<std::size_t>(k) - 1]);
  }
  // On the take at tempo 1 the capture time of a frame is its template frame / 60: timestamps
  // are never early, at most 1.5 periods + jitter late, and some are late.
  const Performance steady = with_frame_loss(play(source, {}), {0.10, 0.20, 1.5, 0.002, 3});
  int late = 0;
  for (int k = 0; k < steady.frame_count(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double lateness = steady.times_s[i] - steady.truth[i].template_frame / 60.0;
    EXPECT_GE(lateness, -1e-9);
    EXPECT_LE(lateness, 1.5 / 60.0 + 0.002 + 1e-3);
    late += lateness > 0.003 ? 1 : 0;
  }
  EXPECT_NEAR(static_cast<double>(late) / steady.frame_count(), 0.2 * (1.0 - 3.0 / 25.0), 0.05);
  EXPECT_EQ(lossy.truth.size(), static_cast<std::size_t>(lossy.frame_count()));
  EXPECT_EQ(lossy.times_s.size(), static_cast<std::size_t>(lossy.frame_count()));
}

TEST(Perturbations, RepeatedFramesShowThePreviousPoseAndPassTheJumpOn) {
  const Fixture f = make_fixture(1800);
  const SourceTake source = f.source();
  const Performance full = improvise(std::span(&source, 1), improv_options(0.0)).value();
  FrameLossOptions options;
  options.repeat_fraction = 0.03;
  options.seed = 5;
  ASSERT_TRUE(options.active());
  const Performance repeated = with_frame_loss(full, options);
  ASSERT_EQ(repeated.frame_count(), full.frame_count());  // nothing dropped
  int repeats = 0;
  for (int k = 0; k < full.frame_count(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    EXPECT_DOUBLE_EQ(repeated.times_s[i], full.times_s[i]);  // sent on time, stale
    const bool same_as_source =
        repeated.motion.rotations_ls(k)[1].isApprox(full.motion.rotations_ls(k)[1], 1e-12) &&
        repeated.truth[i].template_frame == full.truth[i].template_frame;
    if (same_as_source) continue;
    ++repeats;
    ASSERT_GT(k, 0);
    EXPECT_TRUE(
        repeated.motion.rotations_ls(k)[1].isApprox(repeated.motion.rotations_ls(k - 1)[1], 0.0));
    EXPECT_EQ(repeated.truth[i].template_frame, repeated.truth[i - 1].template_frame);
    EXPECT_FALSE(repeated.truth[i].jump);
  }
  EXPECT_NEAR(static_cast<double>(repeats) / full.frame_count(), 0.03, 0.01);
  EXPECT_EQ(count_jumps(repeated), count_jumps(full));  // a repeated jump frame passes its flag on
  // Without repeats, the other perturbations draw the very same numbers as before.
  const Performance lossy = with_frame_loss(full, {0.10, 0.20, 1.5, 0.002, 3});
  FrameLossOptions same{0.10, 0.20, 1.5, 0.002, 3};
  same.repeat_fraction = 0.0;
  EXPECT_EQ(with_frame_loss(full, same).times_s, lossy.times_s);
}

// Whether frame a of one clip and frame b of another hold the same pose, bit for bit.
bool same_pose(const Clip& one, int a, const Clip& other, int b) {
  const auto t0 = one.translations_ls(a), t1 = other.translations_ls(b);
  const auto r0 = one.rotations_ls(a), r1 = other.rotations_ls(b);
  for (std::size_t j = 0; j < t0.size(); ++j) {
    if (t0[j] != t1[j] || r0[j].coeffs() != r1[j].coeffs()) return false;
  }
  return true;
}

TEST(Perturbations, StallsHoldThePoseWhileTheTruthMovesOn) {
  const Fixture f = make_fixture(1800);
  const SourceTake source = f.source();
  const Performance full = improvise(std::span(&source, 1), improv_options(0.0)).value();  // 40 s
  FrameLossOptions options;
  options.freeze_every_s = 4.0;
  options.seed = 3;
  ASSERT_TRUE(options.active());
  const Performance stalled = with_frame_loss(full, options);
  ASSERT_EQ(stalled.frame_count(), full.frame_count());  // every frame is sent
  int held = 0, spans = 0;
  for (int k = 0; k < full.frame_count(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    EXPECT_DOUBLE_EQ(stalled.times_s[i], full.times_s[i]);
    // The dancer dances on: the truth is the dancer's own frame, held or not.
    EXPECT_EQ(stalled.truth[i].template_frame, full.truth[i].template_frame);
    EXPECT_EQ(stalled.truth[i].jump, full.truth[i].jump);
    if (same_pose(stalled.motion, k, full.motion, k)) continue;
    ASSERT_GT(k, 0);
    ++held;
    // Bit for bit the pose before, which is the last one the sensor saw.
    EXPECT_TRUE(same_pose(stalled.motion, k, stalled.motion, k - 1)) << k;
    spans += same_pose(stalled.motion, k - 1, full.motion, k - 1) ? 1 : 0;  // a span's first
  }
  // 0.3-2 s (mean 1.15 s) every 4 s on average: about a fifth of the frames, in a few spans.
  EXPECT_NEAR(static_cast<double>(held) / full.frame_count(), 1.15 / (4.0 + 1.15), 0.12);
  EXPECT_GE(spans, 3);
  EXPECT_LE(static_cast<double>(held) / spans, 2.0 * 60.0);
  // Without stalls, the other perturbations draw the very same numbers as before.
  FrameLossOptions same{0.10, 0.20, 1.5, 0.002, 3};
  const Performance lossy = with_frame_loss(full, same);
  same.freeze_every_s = 0.0;
  EXPECT_EQ(with_frame_loss(full, same).times_s, lossy.times_s);
}

TEST(Perturbations, TrackingLossesDropWholeSpansAndPassTheJumpOn) {
  const Fixture f = make_fixture(1800);  // 30 s at 60 Hz
  const SourceTake source = f.source();
  const Performance full = improvise(std::span(&source, 1), improv_options(0.0)).value();
  FrameLossOptions options;
  options.gap_every_s = 4.0;
  options.seed = 7;
  ASSERT_TRUE(options.active());
  const Performance lossy = with_frame_loss(full, options);
  ASSERT_EQ(lossy.truth.size(), static_cast<std::size_t>(lossy.frame_count()));
  EXPECT_DOUBLE_EQ(lossy.times_s.front(), full.times_s.front());  // the first frame is kept
  // Every hole in the timeline is one loss of 0.3-1 s (no burst drops were asked for).
  int gaps = 0;
  double lost_s = 0.0;
  for (std::size_t k = 1; k < lossy.times_s.size(); ++k) {
    const double hole = lossy.times_s[k] - lossy.times_s[k - 1] - 1.0 / 60.0;
    if (hole < 1e-9) continue;
    ++gaps;
    lost_s += hole;
    EXPECT_GE(hole, 0.3 - 1.0 / 60.0 - 1e-9);
    EXPECT_LE(hole, 1.0 + 1.0 / 60.0 + 1e-9);
  }
  // About 30 / (4 + 0.65) losses; what is kept is what is not lost.
  EXPECT_GE(gaps, 3);
  EXPECT_LE(gaps, 12);
  EXPECT_NEAR(lost_s + lossy.frame_count() / 60.0, full.frame_count() / 60.0, 1e-6);
  const int full_jumps = count_jumps(full), lossy_jumps = count_jumps(lossy);
  // A jump inside a loss passes its flag on (unless the loss ran to the end).
  EXPECT_GE(lossy_jumps, full_jumps - 1);
  EXPECT_LE(lossy_jumps, full_jumps);
}

TEST(EvalCases, HarshCaseAndNoiseSweepHaveIssue11sMagnitudes) {
  const std::vector<EvalCase> cases = standard_cases();
  const auto harsh = std::ranges::find(cases, std::string("harsh"), &EvalCase::name);
  ASSERT_NE(harsh, cases.end());
  EXPECT_TRUE(harsh->recipe.improvise);
  EXPECT_DOUBLE_EQ(harsh->recipe.improvise_options.rate_hz, 30.0);
  EXPECT_NEAR(harsh->recipe.noise.rotation_deg, 4.0 * std::sqrt(3.0), 1e-12);  // 4 per axis
  EXPECT_DOUBLE_EQ(harsh->recipe.noise.position_m, 0.01);
  EXPECT_DOUBLE_EQ(harsh->recipe.loss.repeat_fraction, 0.03);
  EXPECT_DOUBLE_EQ(harsh->recipe.body_scale.value_or(0.0), 1.1);
  // Fixed: a gentler --noise-deg does not soften it.
  CaseSettings gentle;
  gentle.noise_rotation_deg = 0.5;
  const std::vector<EvalCase> other = standard_cases(gentle);
  EXPECT_EQ(
      std::ranges::find(other, std::string("harsh"), &EvalCase::name)->recipe.noise.rotation_deg,
      harsh->recipe.noise.rotation_deg);

  const std::vector<EvalCase> sweep = noise_sweep_cases();
  ASSERT_EQ(sweep.size(), 6u);
  for (int deg = 0; deg <= 5; ++deg) {
    const EvalCase& c = sweep[static_cast<std::size_t>(deg)];
    EXPECT_EQ(c.name, "noise-sweep-" + std::to_string(deg));
    EXPECT_NEAR(c.recipe.noise.rotation_deg, deg * std::sqrt(3.0), 1e-12);
    EXPECT_EQ(c.recipe.noise.active(), deg > 0);
    EXPECT_TRUE(c.recipe.improvise);
  }

  // The suit sweep: suit-drift's recipe at 0 to 10 degrees, with the settings' noise.
  CaseSettings noisier;
  noisier.noise_rotation_deg = 4.0;
  const std::vector<EvalCase> suits = suit_sweep_cases(noisier);
  ASSERT_EQ(suits.size(), 6u);
  for (int i = 0; i < 6; ++i) {
    const EvalCase& c = suits[static_cast<std::size_t>(i)];
    EXPECT_EQ(c.name, "suit-sweep-" + std::to_string(2 * i));
    EXPECT_DOUBLE_EQ(c.recipe.noise.bias_deg, 2.0 * i);
    EXPECT_DOUBLE_EQ(c.recipe.noise.drift_deg, 2.0 * i);
    EXPECT_DOUBLE_EQ(c.recipe.noise.rotation_deg, 4.0);
    EXPECT_DOUBLE_EQ(c.recipe.noise.position_m, CaseSettings{}.noise_position_m);
    EXPECT_FALSE(c.recipe.improvise);
  }

  // The body sweep: improv-pause with the settings' noise, danced by a 0.8x to 1.2x body.
  const std::vector<EvalCase> bodies = body_sweep_cases(noisier);
  ASSERT_EQ(bodies.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    const EvalCase& c = bodies[static_cast<std::size_t>(i)];
    EXPECT_EQ(c.name, "body-sweep-" + std::to_string(80 + 10 * i));
    EXPECT_DOUBLE_EQ(c.recipe.body_scale.value_or(0.0), 0.8 + 0.1 * i);
    EXPECT_DOUBLE_EQ(c.recipe.noise.rotation_deg, 4.0);
    EXPECT_TRUE(c.recipe.improvise);
    EXPECT_DOUBLE_EQ(c.recipe.improvise_options.pause_prob, 1.0);
  }

  // The rate sweep: improv-pause with the settings' noise, from a 20 to a 240 Hz sensor.
  const std::vector<EvalCase> rates = rate_sweep_cases(noisier);
  const std::vector<int> hz = {20, 25, 30, 50, 60, 72, 90, 120, 240};
  ASSERT_EQ(rates.size(), hz.size());
  for (std::size_t i = 0; i < hz.size(); ++i) {
    const EvalCase& c = rates[i];
    EXPECT_EQ(c.name, "rate-sweep-" + std::to_string(hz[i]));
    EXPECT_DOUBLE_EQ(c.recipe.improvise_options.rate_hz, hz[i]);
    EXPECT_DOUBLE_EQ(c.recipe.noise.rotation_deg, 4.0);
    EXPECT_TRUE(c.recipe.improvise);
    EXPECT_DOUBLE_EQ(c.recipe.improvise_options.pause_prob, 1.0);
  }

  // The tempo sweep: improv-pause with the settings' noise, danced at 0.5x to 1.6x.
  const std::vector<EvalCase> tempi = tempo_sweep_cases(noisier);
  const std::vector<int> percent = {50, 60, 70, 85, 100, 120, 140, 160};
  ASSERT_EQ(tempi.size(), percent.size());
  for (std::size_t i = 0; i < percent.size(); ++i) {
    const EvalCase& c = tempi[i];
    EXPECT_EQ(c.name, "tempo-sweep-" + std::to_string(percent[i]));
    EXPECT_DOUBLE_EQ(c.recipe.improvise_options.tempo.factor, percent[i] / 100.0);
    EXPECT_DOUBLE_EQ(c.recipe.noise.rotation_deg, 4.0);
    EXPECT_TRUE(c.recipe.improvise);
  }

  // A learner on a fast suit: 240 Hz, 0.7x, the noise.
  const auto learner = std::ranges::find(cases, std::string("240hz-slow"), &EvalCase::name);
  ASSERT_NE(learner, cases.end());
  EXPECT_DOUBLE_EQ(learner->recipe.play.rate_hz, 240.0);
  EXPECT_DOUBLE_EQ(learner->recipe.play.tempo.factor, 0.7);
  EXPECT_DOUBLE_EQ(learner->recipe.noise.rotation_deg, CaseSettings{}.noise_rotation_deg);

  // The inertial suit: the default noise plus its calibration error and drift.
  const auto suit = std::ranges::find(cases, std::string("suit-drift"), &EvalCase::name);
  ASSERT_NE(suit, cases.end());
  EXPECT_DOUBLE_EQ(suit->recipe.noise.rotation_deg, CaseSettings{}.noise_rotation_deg);
  EXPECT_DOUBLE_EQ(suit->recipe.noise.bias_deg, 5.0);
  EXPECT_DOUBLE_EQ(suit->recipe.noise.drift_deg, 5.0);

  // A camera pitched down: the noise, in a tilted world.
  const auto tilted = std::ranges::find(cases, std::string("tilted"), &EvalCase::name);
  ASSERT_NE(tilted, cases.end());
  EXPECT_DOUBLE_EQ(tilted->recipe.world_tilt_deg, 12.0);
  EXPECT_TRUE(tilted->recipe.noise.active());
  // An optical system's occluded arms: the noise, and an arm held every 6 s on average.
  const auto occluded = std::ranges::find(cases, std::string("occluded"), &EvalCase::name);
  ASSERT_NE(occluded, cases.end());
  EXPECT_DOUBLE_EQ(occluded->recipe.noise.occlusion_every_s, 6.0);
  EXPECT_GT(occluded->recipe.noise.rotation_deg, 0.0);
}

TEST(Perturbations, ATiltedWorldIsLevelledAsALoadedFileIsAndTheRealWristsTurnWithIt) {
  const Fixture f = make_fixture(300);
  const SourceTake source = f.source();
  PerformanceRecipe recipe;
  recipe.noise = {3.0, 0.01, 0};
  recipe.world_tilt_deg = 12.0;
  const Result<Performance> made = make_performance({&source, 1}, recipe, 5);
  ASSERT_TRUE(made) << made.error().message;
  const Performance& tilted = made.value();
  // Levelled to the floor the toes touch, as load_motion levels a file.
  EXPECT_LT(tilt_from_vertical_deg(detect_up_axis(tilted.motion, tilted.roles).floor_up), 1.0);
  // The real wrists are in that levelled world: within the noise of the sensed ones. Left in the
  // tilted world they would be 12 degrees (about 20 cm at a wrist) away.
  ASSERT_EQ(tilted.true_wrists_ws.size(), static_cast<std::size_t>(tilted.frame_count()));
  const int wrist = tilted.roles[Role::kLeftWrist];
  double sum = 0.0;
  std::vector<Vec3> positions(static_cast<std::size_t>(tilted.motion.joint_count()));
  std::vector<Quat> rotations(positions.size());
  for (int frame = 0; frame < tilted.frame_count(); ++frame) {
    forward_kinematics(tilted.motion.skeleton(), tilted.motion.translations_ls(frame),
                       tilted.motion.rotations_ls(frame), positions, rotations);
    sum += (positions[static_cast<std::size_t>(wrist)] -
            tilted.true_wrists_ws[static_cast<std::size_t>(frame)][0])
               .norm();
  }
  EXPECT_LT(sum / tilted.frame_count(), 0.08) << "metres, mean";

  // The turn level_as_loaded finds is the tilt (this dancer leans little); a level world is left
  // alone.
  Performance again = with_world_tilt(tilted, 12.0);
  EXPECT_NEAR(rad_to_deg(log_map(level_as_loaded(again)).norm()), 12.0, 0.5);
  EXPECT_TRUE(level_as_loaded(again).vec().isZero(0.0));
}

TEST(Perturbations, BodyScaleAndRoomPlacementLeaveTheFeaturesThatShouldNotChange) {
  const Fixture f = make_fixture(300);
  const Performance clean = play(f.source(), {});
  const Performance bigger = with_body_scale(clean, 1.15);
  EXPECT_TRUE(bigger.motion.skeleton().joints[3].offset.isApprox(
      1.15 * clean.motion.skeleton().joints[3].offset));
  EXPECT_TRUE(
      bigger.motion.translations_ls(10)[0].isApprox(1.15 * clean.motion.translations_ls(10)[0]));

  // Another place and facing: the features (posture, velocities in the heading frame, speeds)
  // are the same.
  const Performance moved = with_room_placement(clean, deg_to_rad(135.0), Vec3(2.5, 0.0, -1.5));
  EXPECT_GT((moved.motion.translations_ls(10)[0] - clean.motion.translations_ls(10)[0]).norm(),
            1.0);
  Result<FeatureExtractor> extractor =
      FeatureExtractor::create(clean.motion.skeleton_ptr(), f.roles, FeatureSpec{});
  ASSERT_TRUE(extractor);
  const FeatureMatrix a = extractor.value().extract_clip(clean.motion);
  const FeatureMatrix b = extractor.value().extract_clip(moved.motion);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-3f);
}

TEST(MakePerformance, ComposesImprovisationNoiseAndALowRate) {
  const Fixture f = make_fixture(1800);
  const SourceTake source = f.source();
  PerformanceRecipe recipe;
  recipe.improvise = true;
  recipe.improvise_options = improv_options(1.0);
  recipe.improvise_options.rate_hz = 30.0;
  recipe.noise = {3.0, 0.01, 0};
  recipe.loss = {0.1, 0.2, 1.5, 0.002, 0};
  Result<Performance> p = make_performance(std::span(&source, 1), recipe, 42);
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_DOUBLE_EQ(p.value().motion.frame_rate(), 30.0);
  EXPECT_NEAR(p.value().frame_count(), 40 * 30 * 0.9, 40 * 30 * 0.05);
  int jumps = 0, pauses = 0;
  for (const TruthFrame& t : p.value().truth) {
    jumps += t.jump ? 1 : 0;
    pauses += t.in_pause ? 1 : 0;
  }
  EXPECT_GT(jumps, 3);
  EXPECT_GT(pauses, 0);
  Result<Performance> again = make_performance(std::span(&source, 1), recipe, 42);
  ASSERT_TRUE(again);
  EXPECT_EQ(again.value().times_s, p.value().times_s);
}

TEST(MakePerformance, ABodySizeOnAnotherRigIsThatSizeOfTheTemplateDancer) {
  // Retargeting onto a rig gives the rig's bone lengths: the body is sized after it, or
  // body-size@rig would be the rig's own body (it was). The size is the template dancer's times
  // the factor, whatever the rig's own size: on a rig 1.3x the dancer, 1.15 is 1.15, not 1.5.
  const Fixture f = make_fixture(120);
  const SourceTake source = f.source();
  auto bigger_rig = std::make_shared<Skeleton>(f.clip.skeleton());
  for (Joint& joint : bigger_rig->joints) joint.offset *= 1.3;
  const auto head_to_foot_m = [&](std::shared_ptr<const Skeleton> rig,
                                  std::optional<double> body_scale) {
    PerformanceRecipe recipe;
    recipe.rig = std::move(rig);
    if (recipe.rig) recipe.rig_roles = f.roles;
    recipe.body_scale = body_scale;
    Result<Performance> p = make_performance(std::span(&source, 1), recipe, 3);
    EXPECT_TRUE(p) << p.error().message;
    if (!p) return 0.0;
    const std::vector<Vec3> world = world_positions(p.value().motion);
    return (world[static_cast<std::size_t>(f.roles[Role::kHead])] -
            world[static_cast<std::size_t>(f.roles[Role::kLeftAnkle])])
        .norm();
  };
  const double dancer = head_to_foot_m(nullptr, std::nullopt);
  ASSERT_GT(dancer, 0.5);
  EXPECT_NEAR(head_to_foot_m(nullptr, 1.15) / dancer, 1.15, 1e-6);
  EXPECT_NEAR(head_to_foot_m(bigger_rig, std::nullopt) / dancer, 1.3, 1e-6);  // the rig's own
  EXPECT_NEAR(head_to_foot_m(bigger_rig, 1.15) / dancer, 1.15, 1e-6);
  EXPECT_NEAR(head_to_foot_m(bigger_rig, 1.0) / dancer, 1.0, 1e-6);
  EXPECT_NEAR(head_to_foot_m(f.clip.skeleton_ptr(), 0.9) / dancer, 0.9, 1e-6);
}

// The angle at the elbow (upper arm against forearm) of the left arm at every frame: a property
// of the body that retargeting keeps (every role's direction is kept) and a sensor's errors move.
std::vector<double> left_elbow_angles(const Performance& p) {
  const std::vector<Vec3> world = world_positions(p.motion);
  const auto joints = static_cast<std::size_t>(p.motion.joint_count());
  const auto at = [&](int frame, Role role) {
    return world[static_cast<std::size_t>(frame) * joints +
                 static_cast<std::size_t>(p.roles[role])];
  };
  std::vector<double> angles;
  for (int k = 0; k < p.frame_count(); ++k) {
    const Vec3 upper = at(k, Role::kLeftElbow) - at(k, Role::kLeftShoulder);
    const Vec3 fore = at(k, Role::kLeftWrist) - at(k, Role::kLeftElbow);
    angles.push_back(std::atan2(upper.cross(fore).norm(), upper.dot(fore)));
  }
  return angles;
}

TEST(MakePerformance, TheSensorsErrorsAreTheSameOnEveryRig) {
  // The sensor's errors belong to the dancer's body: the same noisy performance reaches every rig
  // (noise, then retargeting). Put on the delivered rig's joints instead, the proportioned rig's
  // elbow bent up to 8.2 degrees differently from the library rig's under the same sensor.
  const Fixture f = make_fixture(240);
  const SourceTake source = f.source();
  PerformanceRecipe native;
  native.noise.rotation_deg = 4.0;
  native.noise.position_m = 0.01;
  native.noise.bias_deg = 5.0;
  native.noise.drift_deg = 5.0;
  PerformanceRecipe on_rig = native;
  on_rig.rig = std::make_shared<const Skeleton>(
      make_proportioned_rig(f.clip.skeleton(), f.roles, RigProportions::evaluation_variant()));
  on_rig.rig_roles = f.roles;
  Result<Performance> a = make_performance(std::span(&source, 1), native, 9);
  Result<Performance> b = make_performance(std::span(&source, 1), on_rig, 9);
  ASSERT_TRUE(a) << a.error().message;
  ASSERT_TRUE(b) << b.error().message;
  const std::vector<double> native_angles = left_elbow_angles(a.value());
  const std::vector<double> rig_angles = left_elbow_angles(b.value());
  ASSERT_EQ(native_angles.size(), rig_angles.size());
  double largest = 0.0;
  for (std::size_t k = 0; k < native_angles.size(); ++k) {
    largest = std::max(largest, std::abs(native_angles[k] - rig_angles[k]));
  }
  EXPECT_LT(rad_to_deg(largest), 0.01);

  // The scores' true wrists are the noise-free performance's, on the rig.
  PerformanceRecipe clean_on_rig = on_rig;
  clean_on_rig.noise = {};
  Result<Performance> clean = make_performance(std::span(&source, 1), clean_on_rig, 9);
  ASSERT_TRUE(clean);
  const std::vector<Vec3> world = world_positions(clean.value().motion);
  const auto joints = static_cast<std::size_t>(clean.value().motion.joint_count());
  ASSERT_EQ(b.value().true_wrists_ws.size(), static_cast<std::size_t>(clean.value().frame_count()));
  for (int k = 0; k < clean.value().frame_count(); k += 17) {
    const Vec3 wrist = world[static_cast<std::size_t>(k) * joints +
                             static_cast<std::size_t>(f.roles[Role::kLeftWrist])];
    EXPECT_LT((b.value().true_wrists_ws[static_cast<std::size_t>(k)][0] - wrist).norm(), 1e-6) << k;
  }
}

TEST(RecordedPerformance, FrameIIsTheTakesMomentIOverTheRecordingsRate) {
  // A 120 Hz recording of a 60 Hz take, 50 frames longer than the take: frame i is template
  // frame i / 2, and what runs past the take's end is cut off.
  const Fixture take = make_fixture(300);
  const Fixture recording{make_dance(make_role_skeleton(), 120.0, 650),
                          daz_roles(*make_role_skeleton())};
  Result<Performance> made =
      recorded_performance(recording.clip, recording.roles, 5, take.clip.frame_count(), 60.0);
  ASSERT_TRUE(made) << made.error().message;
  const Performance& p = made.value();
  ASSERT_EQ(p.frame_count(), 599);  // moments 0 .. 299 / 60 s at 120 Hz
  ASSERT_EQ(p.truth.size(), 599u);
  EXPECT_EQ(p.truth[0].take, 5);
  EXPECT_DOUBLE_EQ(p.truth[301].template_frame, 150.5);
  EXPECT_DOUBLE_EQ(p.truth.back().template_frame, 299.0);
  EXPECT_DOUBLE_EQ(p.times_s[240], 2.0);
  EXPECT_DOUBLE_EQ(p.template_rate_hz, 60.0);
  EXPECT_EQ(p.motion.rotations_ls(100)[3].coeffs(), recording.clip.rotations_ls(100)[3].coeffs());
  EXPECT_TRUE(p.true_wrists_ws.empty());  // a recording's wrists are the real ones

  // Made into a case: the perturbations of the recipe still apply, and it needs no sources.
  PerformanceRecipe recipe;
  recipe.recorded = std::make_shared<const Performance>(p);
  recipe.noise = {2.0, 0.0, 0};
  Result<Performance> noisy = make_performance({}, recipe, 3);
  ASSERT_TRUE(noisy) << noisy.error().message;
  EXPECT_EQ(noisy.value().frame_count(), 599);
  EXPECT_EQ(noisy.value().true_wrists_ws.size(), 599u);

  // Bad input.
  EXPECT_FALSE(recorded_performance(recording.clip, recording.roles, 5, 1, 60.0));
  EXPECT_FALSE(recorded_performance(recording.clip, recording.roles, 5, 300, 0.0));
  const Fixture one{make_dance(make_role_skeleton(), 120.0, 1), daz_roles(*make_role_skeleton())};
  EXPECT_FALSE(recorded_performance(one.clip, one.roles, 5, 300, 60.0));
}

TEST(MakePerformance, RecordsTheRealWristsBeforeTheNoise) {
  // The partner metrics score the partner's hands against the user's real hands: the wrists as
  // they were before the sensor's noise, kept in step with dropped and repeated frames.
  const Fixture f = make_fixture(1800);
  const SourceTake source = f.source();
  PerformanceRecipe recipe;
  recipe.improvise = true;
  recipe.improvise_options = improv_options(1.0);
  recipe.loss.drop_fraction = 0.1;
  Result<Performance> clean = make_performance(std::span(&source, 1), recipe, 7);
  ASSERT_TRUE(clean) << clean.error().message;
  EXPECT_TRUE(clean.value().true_wrists_ws.empty());  // no noise: the sensed wrists are real

  recipe.noise = {4.0, 0.01, 0};
  Result<Performance> noisy = make_performance(std::span(&source, 1), recipe, 7);
  ASSERT_TRUE(noisy) << noisy.error().message;
  const Performance& p = noisy.value();
  ASSERT_EQ(p.frame_count(), clean.value().frame_count());  // the same frames dropped
  ASSERT_EQ(p.true_wrists_ws.size(), static_cast<std::size_t>(p.frame_count()));
  const std::vector<Vec3> real = world_positions(clean.value().motion);
  const std::vector<Vec3> sensed = world_positions(p.motion);
  const auto joints = static_cast<std::size_t>(p.motion.joint_count());
  double sensed_off = 0.0;
  for (std::size_t k = 0; k < p.true_wrists_ws.size(); ++k) {
    for (const auto& [side, role] : {std::pair{0, Role::kLeftWrist}, {1, Role::kRightWrist}}) {
      const std::size_t at = k * joints + static_cast<std::size_t>(f.roles[role]);
      EXPECT_LT((p.true_wrists_ws[k][static_cast<std::size_t>(side)] - real[at]).norm(), 1e-9)
          << "frame " << k;
      sensed_off += (sensed[at] - real[at]).norm();
    }
  }
  EXPECT_GT(sensed_off / (2.0 * static_cast<double>(p.true_wrists_ws.size())), 0.01);

  recipe.loss.repeat_fraction = 0.1;  // a repeated frame: the real wrist moved on
  Result<Performance> repeated = make_performance(std::span(&source, 1), recipe, 7);
  ASSERT_TRUE(repeated);
  ASSERT_EQ(repeated.value().true_wrists_ws.size(),
            static_cast<std::size_t>(repeated.value().frame_count()));
  int moved_on = 0;
  for (std::size_t k = 1; k < repeated.value().true_wrists_ws.size(); ++k) {
    const bool same_pose = repeated.value().motion.rotations_ls(static_cast<int>(k))[1].isApprox(
        repeated.value().motion.rotations_ls(static_cast<int>(k) - 1)[1], 0.0);
    if (same_pose &&
        repeated.value().true_wrists_ws[k][0] != repeated.value().true_wrists_ws[k - 1][0]) {
      ++moved_on;
    }
  }
  EXPECT_GT(moved_on, 0);
}

TEST(MakePerformance, ThreePointsCarryTheToldHeadHeightThroughLostFrames) {
  // --tell-head-height: the follower is told the performer's head height standing (the highest
  // the head is over the performance), a calibration; dropped frames keep it.
  const Fixture f = make_fixture(600);
  const SourceTake source = f.source();
  PerformanceRecipe recipe;
  recipe.head_hands = true;
  recipe.loss.drop_fraction = 0.1;
  Result<Performance> untold = make_performance(std::span(&source, 1), recipe, 5);
  ASSERT_TRUE(untold) << untold.error().message;
  EXPECT_EQ(untold.value().told_head_height_m, 0.0);

  recipe.told_head_height_factor = 1.05;
  recipe.body_scale = 0.9;
  Result<Performance> told = make_performance(std::span(&source, 1), recipe, 5);
  ASSERT_TRUE(told) << told.error().message;
  const double highest = highest_head_m(f.clip, f.roles);
  ASSERT_GT(highest, 0.5);
  EXPECT_NEAR(told.value().told_head_height_m, 1.05 * 0.9 * highest, 1e-6 * highest);
}

// Salsa take 60_10's leader at 60 Hz, loaded once: a real dancer who travels the room.
const LoadedMotion& take_60_10() {
  static const LoadedMotion take = [] {
    MotionLoadOptions load;
    load.frame_rate = 60.0;
    Result<LoadedMotion> loaded =
        load_motion({std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/60/60_10_scaled.bvh"}, load);
    EXPECT_TRUE(loaded) << loaded.error().message;
    return loaded ? std::move(loaded).value() : LoadedMotion{};
  }();
  return take;
}

TEST(MakePerformance, ThreePointsInATiltedWorldAreLevelledAsTheirRecordingIsTruthsAndAll) {
  // A camera-based three-point tracker pitched down: the points are levelled from the head's
  // path as loading their CSV levels them (level_head_path_as_loaded), and the scores' real
  // wrists, body headings and the told head height are in that level world too. A real take,
  // whose dancer travels the room (the evidence of the head's path).
  const LoadedMotion& take = take_60_10();
  ASSERT_GT(take.clip.frame_count(), 0);
  const SourceTake source{0, &take.clip, take.roles};
  PerformanceRecipe recipe;
  recipe.head_hands = true;
  recipe.told_head_height_factor = 1.0;
  Result<Performance> level = make_performance(std::span(&source, 1), recipe, 3);
  ASSERT_TRUE(level) << level.error().message;
  recipe.world_tilt_deg = 12.0;
  Result<Performance> tilted = make_performance(std::span(&source, 1), recipe, 3);
  ASSERT_TRUE(tilted) << tilted.error().message;
  const Performance& p = tilted.value();

  EXPECT_TRUE(head_path_levelling(p.motion, kPointsHead).vec().isZero(0.0)) << "levelled";
  EXPECT_NEAR(p.told_head_height_m, level.value().told_head_height_m, 0.03);
  ASSERT_EQ(p.true_wrists_ws.size(), static_cast<std::size_t>(p.frame_count()));
  ASSERT_EQ(p.true_headings_ws.size(), static_cast<std::size_t>(p.frame_count()));
  double wrist_off = 0.0, most_lean_deg = 0.0;
  std::vector<Vec3> positions(static_cast<std::size_t>(p.motion.joint_count()));
  std::vector<Quat> rotations(positions.size());
  for (int f = 0; f < p.frame_count(); ++f) {
    forward_kinematics(p.motion.skeleton(), p.motion.translations_ls(f), p.motion.rotations_ls(f),
                       positions, rotations);
    const auto k = static_cast<std::size_t>(f);
    wrist_off += (positions[kPointsLeftHand] - p.true_wrists_ws[k][0]).norm();
    most_lean_deg = std::max(
        most_lean_deg, tilt_from_vertical_deg(p.true_headings_ws[k].rotation * Vec3::UnitY()));
  }
  // The hands are the wrists plus 5 mm of tracking noise; left tilted, the real wrists would be a
  // 12-degree turn (about 20 cm a metre from the origin) away.
  EXPECT_LT(wrist_off / p.frame_count(), 0.03) << "metres, mean";
  EXPECT_LT(most_lean_deg, 3.0) << "a body heading frame stands upright";
}

TEST(Improvise, RealTakeKeepsTheRootPathContinuous) {
  const LoadedMotion& take = take_60_10();
  ASSERT_GT(take.clip.frame_count(), 0);
  const SourceTake source{0, &take.clip, take.roles};
  double max_step = 0.0, max_turn = 0.0;
  take_steps(take.clip, max_step, max_turn);
  for (const double pause : {0.0, 1.0}) {
    const Performance p = improvise(std::span(&source, 1), improv_options(pause)).value();
    for (int k = 1; k < p.frame_count(); ++k) {
      Vec3 step = p.motion.translations_ls(k)[0] - p.motion.translations_ls(k - 1)[0];
      step.y() = 0.0;
      EXPECT_LE(step.norm(), 1.05 * max_step + 0.002) << "frame " << k;
      if (!p.truth[static_cast<std::size_t>(k)].in_pause) {
        expect_same_pose_up_to_rigid(p, take.clip, k);
      }
    }
  }
}

}  // namespace
}  // namespace duet
