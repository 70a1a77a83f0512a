// Per-frame cost of partner synthesis (method.md 5-6). Budget: < 100 us per frame with every
// correction on, for the 43-joint CMU salsa skeleton (57 joints with End Sites). The cost is
// linear in the joint count (smoothing, blending, one forward kinematics pass) plus a constant
// for the two arm IK solves and the foot lock.
//
// BM_Synthesis/<set>: a synthetic 43-joint humanoid, hands in contact, a jump every 100 frames;
//   <set> is one correction alone (align, contact, smooth, footlock, blend), none, or all.
// BM_SynthesisSalsa: the real pair 60_01 / 61_01 (skipped without DUET_DATA_DIR data), the user
//   dancing the leader's part elsewhere in the room.
// BM_IkTwoBone: one two-bone IK solve.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "../tests/partner/synthetic_partner.h"
#include "duet/io/bvh.h"
#include "duet/partner/ik_two_bone_job.h"
#include "duet/partner/partner_synthesis.h"

namespace duet {
namespace {

const char* const kSets[] = {"none", "align", "contact", "smooth", "footlock", "blend", "all"};

struct Scene {
  Clip leader;
  Clip follower;
  JointRoles leader_roles;
  JointRoles follower_roles;
  std::vector<UserPose> users;  // per frame
};

void add_users(Scene& scene, const Transform& room) {
  const Skeleton& skeleton = scene.leader.skeleton();
  std::vector<Vec3> t(skeleton.joints.size()), p(t.size());
  std::vector<Quat> r(t.size()), q(t.size());
  for (int f = 0; f < scene.leader.frame_count(); ++f) {
    std::copy(scene.leader.translations_ls(f).begin(), scene.leader.translations_ls(f).end(),
              t.begin());
    std::copy(scene.leader.rotations_ls(f).begin(), scene.leader.rotations_ls(f).end(), r.begin());
    t[0] = room.apply(t[0]);
    r[0] = room.rotation * r[0];
    forward_kinematics(skeleton, t, r, p, q);
    scene.users.push_back(user_pose_from_world(p, q, scene.leader_roles));
  }
}

Scene synthetic_scene() {
  const auto skeleton = test::make_humanoid();
  const int frames = 600;
  Scene s{test::make_standing_clip(skeleton, frames),
          test::make_standing_clip(skeleton, frames),
          test::humanoid_roles(*skeleton),
          test::humanoid_roles(*skeleton),
          {}};
  const test::WorldPose rest = test::world_pose(s.leader, 0);
  const Vec3 from_root =
      rest.positions[static_cast<std::size_t>(s.follower_roles[Role::kRightWrist])] -
      rest.positions[0];
  for (int f = 0; f < frames; ++f) {
    // Hands held, the follower swaying and sliding a little, elbows moving.
    const double phase = 0.05 * f;
    s.follower.translations_ls(f)[0] =
        rest.positions[static_cast<std::size_t>(s.leader_roles[Role::kLeftWrist])] - from_root +
        Vec3(0.02 * std::sin(phase), 0.0, 0.0005 * f);
    for (Quat& q : s.follower.rotations_ls(f)) {
      q = (q * quat_from_axis_angle(Vec3::UnitX(), 0.05 * std::sin(phase))).normalized();
    }
  }
  add_users(s, Transform{yaw_rotation(0.7), Vec3(1.0, 0.0, 2.0)});
  for (UserPose& u : s.users) u.wrist_positions_ws[0] += Vec3(0.0, 0.05, 0.0);
  return s;
}

void run_synthesis(benchmark::State& state, const Scene& scene, const PartnerParams& params) {
  const Result<PartnerModel> model =
      PartnerModel::build(scene.leader, scene.leader_roles, scene.follower, scene.follower_roles);
  if (!model.ok()) {
    state.SkipWithError(model.error().message.c_str());
    return;
  }
  const int joints = scene.follower.joint_count();
  PartnerContext context(joints);
  std::vector<Vec3> t(static_cast<std::size_t>(joints));
  std::vector<Quat> r(static_cast<std::size_t>(joints));
  const int frames = scene.follower.frame_count();
  int i = 0;
  for (auto _ : state) {
    const int frame = i % frames;
    PartnerSynthesisJob job;
    job.model = &model.value();
    job.params = &params;
    job.frame = frame;
    job.frame_position = frame;  // the playhead's real frame, as LiveLoop passes it
    job.jumped = i % 100 == 0;
    job.dt_s = 1.0 / 60;
    job.translations_ls = scene.follower.translations_ls(frame);
    job.rotations_ls = scene.follower.rotations_ls(frame);
    job.user = &scene.users[static_cast<std::size_t>(frame)];
    job.context = &context;
    job.translations_ls_out = t;
    job.rotations_ls_out = r;
    benchmark::DoNotOptimize(job.run());
    benchmark::DoNotOptimize(r.data());
    ++i;
  }
  state.counters["joints"] = joints;  // Time per iteration is the cost of one frame
}

void BM_Synthesis(benchmark::State& state) {
  static const Scene scene = synthetic_scene();
  const char* set = kSets[state.range(0)];
  PartnerParams params;
  if (!parse_corrections(set, params).ok()) {
    state.SkipWithError("bad set");
    return;
  }
  state.SetLabel(set);
  run_synthesis(state, scene, params);
}
BENCHMARK(BM_Synthesis)->DenseRange(0, 6);

// 60_01 / 61_01, the user 3 m away and turned by 2 rad; null without the salsa data.
const Scene* salsa_scene() {
  const std::string dir = std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/";
  if (!std::filesystem::exists(dir + "60/60_01_scaled.bvh")) return nullptr;
  static const Scene scene = [&] {
    BvhReadOptions options;
    options.frame_rate = 60.0;
    options.scale = 1.0 / 0.768;
    Scene s{read_bvh(dir + "60/60_01_scaled.bvh", options).value(),
            read_bvh(dir + "61/61_01_scaled.bvh", options).value(),
            {},
            {},
            {}};
    std::string error;
    detect_roles(s.leader.skeleton(), s.leader_roles, error);
    detect_roles(s.follower.skeleton(), s.follower_roles, error);
    add_users(s, Transform{yaw_rotation(2.0), Vec3(3.0, 0.0, -1.0)});
    return s;
  }();
  return &scene;
}

// The live synthesis on the salsa scene with `params`; skipped without the salsa data.
void run_salsa_synthesis(benchmark::State& state, const PartnerParams& params, const char* label) {
  const Scene* scene = salsa_scene();
  if (scene == nullptr) {
    state.SkipWithError("no salsa data in DUET_DATA_DIR");
    return;
  }
  state.SetLabel(label);
  run_synthesis(state, *scene, params);
}

void BM_SynthesisSalsa(benchmark::State& state) {
  run_salsa_synthesis(state, PartnerParams{}, "all, 60_01/61_01");
}
BENCHMARK(BM_SynthesisSalsa);

// The same without the reach through a jump's blend (stage 5b, docs/partner.md "Reach"): what
// the reach costs, with a jump every 100 frames.
void BM_SynthesisSalsaNoReach(benchmark::State& state) {
  PartnerParams params;
  params.reach_s = 0.0;
  run_salsa_synthesis(state, params, "all but the reach, 60_01/61_01");
}
BENCHMARK(BM_SynthesisSalsaNoReach);

// The same with the user's heading filtered as it is, not relative to the template's
// (PartnerParams::smooth_relative_to_template): what filtering it relative to the template costs.
void BM_SynthesisSalsaPlainHeading(benchmark::State& state) {
  PartnerParams params;
  params.smooth_relative_to_template = false;
  run_salsa_synthesis(state, params, "all, the heading filtered as it is, 60_01/61_01");
}
BENCHMARK(BM_SynthesisSalsaPlainHeading);

// The same without the foot hold (docs/partner.md, "Feet through a jump"): what the hold costs,
// with a jump every 100 frames, so feet are held or stepping in part of the frames.
void BM_SynthesisSalsaNoFootHold(benchmark::State& state) {
  PartnerParams params;
  params.foot_hold.enabled = false;
  run_salsa_synthesis(state, params, "all but the foot hold, 60_01/61_01");
}
BENCHMARK(BM_SynthesisSalsaNoFootHold);

void BM_IkTwoBone(benchmark::State& state) {
  const Transform start{quat_from_axis_angle(Vec3::UnitZ(), -1.0), Vec3(0.2, 1.4, 0.0)};
  const Transform mid{quat_from_axis_angle(Vec3::UnitY(), -1.2) * start.rotation,
                      start.apply(Vec3(0.28, 0, 0))};
  const Transform end{mid.rotation, mid.apply(Vec3(0.25, 0, 0))};
  const Quat start_ls = start.rotation, mid_ls = quat_from_axis_angle(Vec3::UnitY(), -1.2);
  Quat start_out, mid_out;
  double k = 0.0;
  for (auto _ : state) {
    IkTwoBoneJob job;
    job.start_joint_ws = &start;
    job.mid_joint_ws = &mid;
    job.end_joint_ws = &end;
    job.start_rotation_ls = &start_ls;
    job.mid_rotation_ls = &mid_ls;
    job.target_ws = end.translation + Vec3(0.05 * std::sin(k), 0.03, -0.02);
    job.start_rotation_ls_out = &start_out;
    job.mid_rotation_ls_out = &mid_out;
    benchmark::DoNotOptimize(job.run());
    benchmark::DoNotOptimize(start_out);
    k += 0.01;
  }
}
BENCHMARK(BM_IkTwoBone);

}  // namespace
}  // namespace duet
