// IkTwoBoneJob, in the manner of ozz-animation's ik_two_bone_job_tests: validation with one input
// removed at a time, then geometric properties: reachable targets are reached under translated,
// rotated and scaled parents (checked by forward kinematics of the corrected local rotations),
// unreachable ones are clamped, the elbow does not flip along a continuous path, degenerate
// chains give no NaN.
#include "duet/partner/ik_two_bone_job.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"

namespace duet {
namespace {

// parent -> shoulder -> elbow -> wrist, bones along +X at rest.
struct Chain {
  Skeleton skeleton;
  std::vector<Vec3> translations_ls;
  std::vector<Quat> rotations_ls;
  std::vector<Vec3> positions_ws;
  std::vector<Quat> rotations_ws;

  static constexpr int kParent = 0, kShoulder = 1, kElbow = 2, kWrist = 3;

  Chain(const Transform& parent, double scale, double upper = 0.3, double lower = 0.25) {
    const Vec3 offsets[] = {Vec3::Zero(), Vec3(0.1, 0.05, 0) * scale, Vec3(upper, 0, 0) * scale,
                            Vec3(lower, 0, 0) * scale};
    for (int j = 0; j < 4; ++j) {
      Joint joint;
      joint.name = "j" + std::to_string(j);
      joint.parent = j - 1;
      joint.offset = offsets[j];
      skeleton.joints.push_back(joint);
      translations_ls.push_back(offsets[j]);
      rotations_ls.push_back(Quat::Identity());
    }
    translations_ls[0] = parent.translation;
    rotations_ls[0] = parent.rotation;
    // A bent, twisted starting pose.
    rotations_ls[kShoulder] = quat_from_euler(Vec3(0.3, -0.4, 0.2), {Axis::kZ, Axis::kX, Axis::kY});
    rotations_ls[kElbow] = quat_from_axis_angle(Vec3::UnitY(), -1.2);
    positions_ws.resize(4);
    rotations_ws.resize(4);
    fk();
  }

  void fk() {
    forward_kinematics(skeleton, translations_ls, rotations_ls, positions_ws, rotations_ws);
  }
  Transform ws(int j) const { return {rotations_ws[j], positions_ws[j]}; }
  double reach() const {
    return (positions_ws[kElbow] - positions_ws[kShoulder]).norm() +
           (positions_ws[kWrist] - positions_ws[kElbow]).norm();
  }
};

struct Solve {
  bool ok = false;
  bool reached = false;
  Vec3 end_ws = Vec3::Zero();
};

// Runs the job on the chain, writes the corrected local rotations back and redoes FK.
Solve solve(Chain& c, const Vec3& target, double weight = 1.0, double swivel = 0.0,
            double soft_reach = 0.0) {
  const Transform s = c.ws(Chain::kShoulder), m = c.ws(Chain::kElbow), e = c.ws(Chain::kWrist);
  Solve out;
  IkTwoBoneJob job;
  job.start_joint_ws = &s;
  job.mid_joint_ws = &m;
  job.end_joint_ws = &e;
  job.start_rotation_ls = &c.rotations_ls[Chain::kShoulder];
  job.mid_rotation_ls = &c.rotations_ls[Chain::kElbow];
  job.target_ws = target;
  job.weight = weight;
  job.swivel_offset_rad = swivel;
  job.soft_reach = soft_reach;
  job.start_rotation_ls_out = &c.rotations_ls[Chain::kShoulder];  // in place
  job.mid_rotation_ls_out = &c.rotations_ls[Chain::kElbow];
  job.reached = &out.reached;
  job.end_position_ws = &out.end_ws;
  out.ok = job.run();
  c.fk();
  return out;
}

bool finite_pose(const Chain& c) {
  for (int j = 0; j < 4; ++j) {
    if (!c.positions_ws[j].allFinite() || !c.rotations_ws[j].coeffs().allFinite()) return false;
    if (std::abs(c.rotations_ls[j].norm() - 1.0) > 1e-9) return false;
  }
  return true;
}

TEST(IkTwoBoneJob, ValidatesEveryInput) {
  Chain c(Transform(), 1.0);
  const Transform s = c.ws(1), m = c.ws(2), e = c.ws(3);
  Quat start_out, mid_out;
  IkTwoBoneJob full;
  full.start_joint_ws = &s;
  full.mid_joint_ws = &m;
  full.end_joint_ws = &e;
  full.start_rotation_ls = &c.rotations_ls[1];
  full.mid_rotation_ls = &c.rotations_ls[2];
  full.target_ws = Vec3(0.3, 0.2, 0.1);
  full.start_rotation_ls_out = &start_out;
  full.mid_rotation_ls_out = &mid_out;
  EXPECT_EQ(full.validate(), "");
  EXPECT_TRUE(full.run());

  const auto expect_fails = [](IkTwoBoneJob job, const char* what) {
    const std::string_view reason = job.validate();
    EXPECT_NE(reason.find(what), std::string_view::npos) << "reason: '" << reason << "'";
    EXPECT_FALSE(job.run());
  };
  IkTwoBoneJob job = full;
  job.start_joint_ws = nullptr;
  expect_fails(job, "start_joint_ws");
  job = full;
  job.mid_joint_ws = nullptr;
  expect_fails(job, "mid_joint_ws");
  job = full;
  job.end_joint_ws = nullptr;
  expect_fails(job, "end_joint_ws");
  job = full;
  job.start_rotation_ls = nullptr;
  expect_fails(job, "start_rotation_ls");
  job = full;
  job.mid_rotation_ls = nullptr;
  expect_fails(job, "mid_rotation_ls");
  job = full;
  job.start_rotation_ls_out = nullptr;
  expect_fails(job, "start_rotation_ls_out");
  job = full;
  job.mid_rotation_ls_out = nullptr;
  expect_fails(job, "mid_rotation_ls_out");
  job = full;
  job.target_ws = IkTwoBoneJob().target_ws;  // never set
  expect_fails(job, "target_ws");
  job = full;
  job.weight = std::nan("");
  expect_fails(job, "weight");
  job = full;
  job.swivel_offset_rad = INFINITY;
  expect_fails(job, "swivel");
  for (const double soft : {-0.1, 1.5, static_cast<double>(NAN)}) {
    job = full;
    job.soft_reach = soft;
    expect_fails(job, "soft_reach");
  }
  // Not-unit rotations and non-finite transforms are bad input too.
  const Quat scaled(2.0, 0.0, 0.0, 0.0);
  job = full;
  job.start_rotation_ls = &scaled;
  expect_fails(job, "start_rotation_ls");
  Transform broken = s;
  broken.translation.x() = std::nan("");
  job = full;
  job.start_joint_ws = &broken;
  expect_fails(job, "start_joint_ws");
  // Optional outputs may be left out.
  job = full;
  job.reached = nullptr;
  job.end_position_ws = nullptr;
  EXPECT_EQ(job.validate(), "");
}

TEST(IkTwoBoneJob, ReachesReachableTargetsUnderTranslatedRotatedScaledParents) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Transform parents[] = {
      Transform(),
      Transform{Quat::Identity(), Vec3(3.0, -2.0, 10.0)},
      Transform{quat_from_euler(Vec3(0.7, -1.9, 2.8), {Axis::kX, Axis::kY, Axis::kZ}),
                Vec3(-1.0, 0.5, 2.0)},
  };
  for (const Transform& parent : parents) {
    for (const double scale : {1.0, 0.01, 25.0}) {
      SCOPED_TRACE(::testing::Message()
                   << "scale " << scale << " parent at " << parent.translation.transpose());
      for (int trial = 0; trial < 50; ++trial) {
        Chain c(parent, scale);
        const double upper = 0.3 * scale, lower = 0.25 * scale;
        // A random direction at a distance strictly inside [upper - lower, upper + lower].
        Vec3 dir(unit(rng), unit(rng), unit(rng));
        if (dir.norm() < 1e-3) continue;
        const double t = 0.02 + 0.96 * (0.5 + 0.5 * unit(rng));
        const double dist = (upper - lower) + t * 2.0 * lower;
        const Vec3 target = c.positions_ws[Chain::kShoulder] + dir.normalized() * dist;
        const Vec3 shoulder_before = c.positions_ws[Chain::kShoulder];
        const Solve r = solve(c, target);
        ASSERT_TRUE(r.ok);
        EXPECT_TRUE(r.reached);
        // Checked through forward kinematics of the output local rotations.
        EXPECT_LT((c.positions_ws[Chain::kWrist] - target).norm(), 1e-9 * scale);
        EXPECT_LT((r.end_ws - target).norm(), 1e-9 * scale);
        // The shoulder stays; the bones keep their lengths.
        EXPECT_LT((c.positions_ws[Chain::kShoulder] - shoulder_before).norm(), 1e-12 * scale);
        EXPECT_NEAR((c.positions_ws[Chain::kElbow] - c.positions_ws[Chain::kShoulder]).norm(),
                    upper, 1e-9 * scale);
        ASSERT_TRUE(finite_pose(c));
      }
    }
  }
}

TEST(IkTwoBoneJob, ClampsUnreachableTargets) {
  for (const double scale : {1.0, 0.01}) {
    // Too far: the arm stretches straight towards the target.
    Chain c(Transform{quat_from_axis_angle(Vec3::UnitY(), 0.5), Vec3(1, 2, 3)}, scale);
    const Vec3 s = c.positions_ws[Chain::kShoulder];
    const Vec3 target = s + Vec3(3.0, -4.0, 1.0) * scale;
    const Solve far = solve(c, target);
    ASSERT_TRUE(far.ok);
    EXPECT_FALSE(far.reached);
    ASSERT_TRUE(finite_pose(c));
    const Vec3 wrist = c.positions_ws[Chain::kWrist];
    EXPECT_NEAR((wrist - s).norm(), 0.55 * scale, 1e-9 * scale);
    EXPECT_NEAR((wrist - s).normalized().dot((target - s).normalized()), 1.0, 1e-9);
    // The elbow is on the straight line too.
    const Vec3 elbow = c.positions_ws[Chain::kElbow];
    EXPECT_NEAR((elbow - s).normalized().dot((target - s).normalized()), 1.0, 1e-6);

    // Too close (inside upper - lower): folded as far as it goes, pointing at the target.
    Chain d(Transform(), scale);
    const Vec3 sd = d.positions_ws[Chain::kShoulder];
    const Vec3 near_target = sd + Vec3(0.0, 0.01, 0.02) * scale;
    const Solve close = solve(d, near_target);
    ASSERT_TRUE(close.ok);
    EXPECT_FALSE(close.reached);
    ASSERT_TRUE(finite_pose(d));
    EXPECT_NEAR((d.positions_ws[Chain::kWrist] - sd).norm(), 0.05 * scale, 1e-9 * scale);
    EXPECT_NEAR(
        (d.positions_ws[Chain::kWrist] - sd).normalized().dot((near_target - sd).normalized()), 1.0,
        1e-9);
  }
}

// The largest elbow displacement between consecutive targets along a long path in front of,
// across and around the shoulder, near and far (some of it out of reach), sampled `steps` times.
// Each solve starts from the same template pose, as in the synthesizer.
double largest_elbow_step(int steps) {
  const Chain rest(Transform(), 1.0);
  const Vec3 s = rest.positions_ws[Chain::kShoulder];
  Vec3 previous = Vec3::Zero();
  double largest = 0.0;
  for (int i = 0; i <= steps; ++i) {
    const double u = static_cast<double>(i) / steps;
    const double angle = -2.0 + 4.0 * u;  // radians about the vertical
    const double dist = 0.1 + 0.5 * (0.5 + 0.5 * std::sin(9.0 * u));
    const Vec3 target =
        s + dist * Vec3(std::cos(angle), 0.6 * std::sin(5.0 * u), std::sin(angle)).normalized();
    Chain c = rest;
    EXPECT_TRUE(solve(c, target).ok);
    EXPECT_TRUE(finite_pose(c));
    const Vec3 elbow = c.positions_ws[Chain::kElbow];
    if (i > 0) largest = std::max(largest, (elbow - previous).norm());
    previous = elbow;
  }
  return largest;
}

TEST(IkTwoBoneJob, ElbowDoesNotFlipAlongAContinuousPath) {
  // A flip is a jump of the elbow that stays however finely the path is sampled; a continuous
  // elbow moves less per sample as the samples get closer. (Near full extension the elbow moves
  // like the square root of the target's distance change, so a ratio to the target step would
  // not be bounded; the shrinking is.)
  const double coarse = largest_elbow_step(2000);
  const double fine = largest_elbow_step(16000);
  EXPECT_LT(fine, 0.5 * coarse);
  EXPECT_LT(fine, 0.01);  // metres, for a 0.55 m arm
}

// Solves from the template pose towards a target `distance` from the shoulder (along a fixed
// direction) with the given soft reach; returns the elbow's interior angle and where the wrist
// lands.
struct SoftSolve {
  double elbow_angle_rad = 0.0;
  Vec3 wrist_ws = Vec3::Zero();
  Vec3 shoulder_ws = Vec3::Zero();
};
SoftSolve solve_at_distance(double distance, double soft_reach) {
  Chain c(Transform(), 1.0);
  const Vec3 s = c.positions_ws[Chain::kShoulder];
  const Vec3 direction = Vec3(0.6, -0.3, 0.5).normalized();
  EXPECT_TRUE(solve(c, s + distance * direction, 1.0, 0.0, soft_reach).ok);
  const Vec3 upper = c.positions_ws[Chain::kShoulder] - c.positions_ws[Chain::kElbow];
  const Vec3 lower = c.positions_ws[Chain::kWrist] - c.positions_ws[Chain::kElbow];
  return {std::acos(std::clamp(upper.normalized().dot(lower.normalized()), -1.0, 1.0)),
          c.positions_ws[Chain::kWrist], s};
}

TEST(IkTwoBoneJob, SoftReachEasesTheLastShareOfTheReach) {
  const double length = 0.55, soft = 0.1;
  const double soft_length = soft * length, hard = length - soft_length;
  // Within the hard share the target is reached exactly.
  const SoftSolve inside = solve_at_distance(0.8 * length, soft);
  EXPECT_NEAR((inside.wrist_ws - inside.shoulder_ws).norm(), 0.8 * length, 1e-9);
  // Beyond it the wrist lands short, on the eased distance, pointing at the target; and however
  // far the target, the arm never quite straightens (up to the full length, the elbow stays bent
  // by a few degrees).
  for (const double distance : {0.95 * length, length, 2.0 * length}) {
    const SoftSolve eased = solve_at_distance(distance, soft);
    const double expected = hard + soft_length * (1.0 - std::exp(-(distance - hard) / soft_length));
    EXPECT_NEAR((eased.wrist_ws - eased.shoulder_ws).norm(), expected, 1e-9) << distance;
    EXPECT_LT((eased.wrist_ws - eased.shoulder_ws).norm(), std::min(distance, length));
    if (distance <= length) {
      EXPECT_LT(eased.elbow_angle_rad, kPi - 0.05) << distance;
    }
  }
  // Why: over the last millimetre before full extension the hard reach turns the elbow by
  // several degrees (a target jittering by a millimetre there flicks the forearm); the soft one
  // by a small fraction of that.
  const double hard_turn = std::abs(solve_at_distance(length, 0.0).elbow_angle_rad -
                                    solve_at_distance(length - 0.001, 0.0).elbow_angle_rad);
  const double soft_turn = std::abs(solve_at_distance(length, soft).elbow_angle_rad -
                                    solve_at_distance(length - 0.001, soft).elbow_angle_rad);
  EXPECT_GT(hard_turn, 0.08);  // radians: about 7 degrees for this 0.30 + 0.25 m arm
  EXPECT_LT(soft_turn, 0.1 * hard_turn);
  // Soft reach 0 is the hard reach: a reachable target is reached at full extension.
  const SoftSolve straight = solve_at_distance(length, 0.0);
  EXPECT_NEAR((straight.wrist_ws - straight.shoulder_ws).norm(), length, 1e-9);
}

TEST(IkTwoBoneJob, KeepsTheElbowOnTheTemplateSide) {
  // For targets near the current wrist the elbow stays on the side it points to in the
  // template pose (the swivel is taken from the pose, not from a fixed default).
  const Chain rest(Transform(), 1.0);
  const Vec3 s = rest.positions_ws[Chain::kShoulder];
  const Vec3 w = rest.positions_ws[Chain::kWrist];
  const Vec3 axis = (w - s).normalized();
  const Vec3 side_before = (rest.positions_ws[Chain::kElbow] - s) -
                           axis * axis.dot(rest.positions_ws[Chain::kElbow] - s);
  for (const Vec3& delta : {Vec3(0.05, 0, 0), Vec3(0, -0.05, 0.02), Vec3(-0.03, 0.04, -0.05)}) {
    Chain c = rest;
    const Vec3 target = w + delta;
    ASSERT_TRUE(solve(c, target).ok);
    const Vec3 a = (target - s).normalized();
    const Vec3 side =
        (c.positions_ws[Chain::kElbow] - s) - a * a.dot(c.positions_ws[Chain::kElbow] - s);
    EXPECT_GT(side.normalized().dot(side_before.normalized()), 0.9);
  }
}

TEST(IkTwoBoneJob, DegenerateInputsGiveNoNaN) {
  // Target at the shoulder.
  {
    Chain c(Transform(), 1.0);
    const Solve r = solve(c, c.positions_ws[Chain::kShoulder]);
    ASSERT_TRUE(r.ok);
    EXPECT_TRUE(finite_pose(c));
    EXPECT_TRUE(r.end_ws.allFinite());
  }
  // Straight arm, target straight along it (no plane to bend in), near and far.
  for (const double dist : {0.2, 0.55, 2.0}) {
    Chain c(Transform(), 1.0);
    c.rotations_ls[Chain::kElbow] = Quat::Identity();
    c.fk();
    const Vec3 s = c.positions_ws[Chain::kShoulder];
    const Vec3 dir = (c.positions_ws[Chain::kWrist] - s).normalized();
    const Solve r = solve(c, s + dir * dist);
    ASSERT_TRUE(r.ok);
    EXPECT_TRUE(finite_pose(c));
    if (dist < 0.55) {
      EXPECT_LT((c.positions_ws[Chain::kWrist] - (s + dir * dist)).norm(), 1e-9);
    }
  }
  // Straight arm, target exactly behind the shoulder.
  {
    Chain c(Transform(), 1.0);
    c.rotations_ls[Chain::kElbow] = Quat::Identity();
    c.fk();
    const Vec3 s = c.positions_ws[Chain::kShoulder];
    const Vec3 dir = (c.positions_ws[Chain::kWrist] - s).normalized();
    const Solve r = solve(c, s - dir * 0.4);
    ASSERT_TRUE(r.ok);
    EXPECT_TRUE(finite_pose(c));
    EXPECT_LT((c.positions_ws[Chain::kWrist] - (s - dir * 0.4)).norm(), 1e-9);
  }
  // Zero-length bones: upper arm, forearm, both.
  for (const auto& [upper, lower] :
       {std::pair{0.0, 0.25}, std::pair{0.3, 0.0}, std::pair{0.0, 0.0}}) {
    Chain c(Transform(), 1.0, upper, lower);
    const Vec3 target = c.positions_ws[Chain::kShoulder] + Vec3(0.1, 0.3, -0.2);
    const Solve r = solve(c, target);
    ASSERT_TRUE(r.ok);
    EXPECT_TRUE(finite_pose(c));
    const double bone = upper + lower;
    if (bone > 0.0) {
      // The remaining bone points at the target.
      const Vec3 s = c.positions_ws[Chain::kShoulder];
      EXPECT_NEAR((c.positions_ws[Chain::kWrist] - s).normalized().dot((target - s).normalized()),
                  1.0, 1e-9);
    }
  }
}

TEST(IkTwoBoneJob, WeightBlendsFromNoCorrection) {
  const Chain rest(Transform(), 1.0);
  const Vec3 target = rest.positions_ws[Chain::kShoulder] + Vec3(0.1, -0.3, 0.25);
  double previous_error = 1e9;
  for (const double w : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    Chain c = rest;
    const Solve r = solve(c, target, w);
    ASSERT_TRUE(r.ok);
    const double error = (c.positions_ws[Chain::kWrist] - target).norm();
    if (w == 0.0) {
      EXPECT_TRUE(c.rotations_ls[Chain::kShoulder].isApprox(rest.rotations_ls[Chain::kShoulder]));
      EXPECT_TRUE(c.rotations_ls[Chain::kElbow].isApprox(rest.rotations_ls[Chain::kElbow]));
      EXPECT_FALSE(r.reached);
    }
    EXPECT_LT(error, previous_error);
    previous_error = error;
  }
  EXPECT_LT(previous_error, 1e-9);
  // Weights outside [0, 1] are clamped.
  Chain over = rest;
  EXPECT_TRUE(solve(over, target, 3.0).reached);
}

TEST(IkTwoBoneJob, SwivelOffsetTurnsTheElbowAboutTheTargetAxis) {
  const Chain rest(Transform(), 1.0);
  const Vec3 s = rest.positions_ws[Chain::kShoulder];
  const Vec3 target = s + Vec3(0.2, -0.25, 0.2);
  Chain a = rest, b = rest;
  ASSERT_TRUE(solve(a, target, 1.0, 0.0).reached);
  ASSERT_TRUE(solve(b, target, 1.0, kPi / 2).reached);
  EXPECT_LT((b.positions_ws[Chain::kWrist] - target).norm(), 1e-9);
  const Vec3 axis = (target - s).normalized();
  const Vec3 ea = a.positions_ws[Chain::kElbow] - s, eb = b.positions_ws[Chain::kElbow] - s;
  EXPECT_NEAR(axis.dot(ea), axis.dot(eb), 1e-9);  // same circle
  const Vec3 pa = ea - axis * axis.dot(ea), pb = eb - axis * axis.dot(eb);
  EXPECT_NEAR(pa.normalized().dot(pb.normalized()), 0.0, 1e-9);  // a quarter turn apart
  EXPECT_GT(axis.dot(pa.cross(pb)), 0.0);                        // right-hand rule
}

}  // namespace
}  // namespace duet
