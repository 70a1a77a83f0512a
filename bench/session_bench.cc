// Per-frame cost of following on real data (method.md 6, first half of the loop): features from
// the user's pose, standardisation (and the rig's posture offset), the HMM forward step, against
// the whole salsa library (14 duets, 27,495 states). Skipped without the data.
//
// BM_FollowSessionStep/0: take 01 on the library's own rig (DAZ BVH, 43 joints).
// BM_FollowSessionStep/1: take 01 on the CMU ASF rig (31 joints).
// BM_FollowSessionStepScalar/*: the same on the scalar kernels (DUET_SIMD=scalar), same run.
// BM_FollowSessionStepHeadHands: take 01 as a headset's three points (head and hands) against the
// library built from the same three points (16 dims).
// BM_FeatureExtract: the full body's features of one frame of take 01 (forward kinematics, the
// canonical body space, the velocity window), with the effector speeds raw (/0) and less the
// sensor's noise (/1, FeatureSpec::debiased_speeds, the default).
// BM_DevicePointsToJoints: one headset pose moved from the devices to the joints (duet serve
// --source xr does it to every xr_pose before the step above).
// BM_WristsOnUserBody: where the user's body puts the wrists at the partner's frame (the live
// loop's contact IK, full body), per frame: take 01's dancer retargeted onto the library's own rig
// (/0) and onto the CMU ASF rig (/1).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "duet/features/feature_extractor.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/simd.h"
#include "duet/io/motion_file.h"
#include "duet/live/duet_library.h"
#include "duet/live/follow_session.h"
#include "duet/live/wrists_on_user_body.h"
#include "duet/motion/device_points.h"
#include "duet/motion/head_hands.h"
#include "salsa_pairs.h"

namespace duet {
namespace {

using bench::kSalsa;

std::optional<DuetLibrary> load_salsa(InputPoints points) {
  LibraryOptions options;
  options.load.frame_rate = 60.0;
  options.features.input_points = points;
  Result<DuetLibrary> loaded = DuetLibrary::load(bench::salsa_pairs(), options);
  if (!loaded) return std::nullopt;
  return std::move(loaded).value();
}

const DuetLibrary* salsa_library(InputPoints points = InputPoints::kFullBody) {
  static const std::optional<DuetLibrary> full = load_salsa(InputPoints::kFullBody);
  static const std::optional<DuetLibrary> head_hands = load_salsa(InputPoints::kHeadHands);
  const std::optional<DuetLibrary>& library =
      points == InputPoints::kHeadHands ? head_hands : full;
  return library ? &*library : nullptr;
}

void follow_session_step(benchmark::State& state, SimdLevel level,
                         InputPoints points = InputPoints::kFullBody) {
  if (!set_simd_level(level)) {
    state.SkipWithError("this CPU cannot run this instruction set");
    return;
  }
  const DuetLibrary* library = salsa_library(points);
  if (library == nullptr) {
    state.SkipWithError("salsa data not found");
    return;
  }
  MotionLoadOptions load;
  load.frame_rate = 60.0;
  const std::vector<std::string> input_files =
      state.range(0) == 0
          ? std::vector<std::string>{kSalsa + "/bvh/60/60_01_scaled.bvh"}
          : std::vector<std::string>{kSalsa + "/asf-amc/60.asf", kSalsa + "/asf-amc/60_01.amc"};
  Result<LoadedMotion> input = load_motion(input_files, load);
  if (!input) {
    state.SkipWithError(input.error().message.c_str());
    return;
  }
  if (points == InputPoints::kHeadHands) {
    Result<Clip> three = head_hands_clip(input.value().clip, input.value().roles);
    if (!three) {
      state.SkipWithError(three.error().message.c_str());
      return;
    }
    input.value().clip = std::move(three).value();
    input.value().roles = head_hands_roles();
  }
  const Clip& clip = input.value().clip;
  Result<HmmFollower> follower = HmmFollower::create(library->model(), FollowParams{});
  Result<FollowSession> session =
      FollowSession::create(*library, clip.skeleton_ptr(), input.value().roles,
                            std::make_unique<HmmFollower>(std::move(follower).value()));
  if (!session) {
    state.SkipWithError(session.error().message.c_str());
    return;
  }
  int f = 0;
  double time_s = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        session.value().step(clip.translations_ls(f), clip.rotations_ls(f), time_s));
    f = (f + 1) % clip.frame_count();
    time_s += 1.0 / 60.0;
  }
  state.counters["states"] = library->model().num_states();
  state.counters["dims"] = library->model().num_dims();
  set_simd_level(detect_simd_level());
}

// The kernels the dispatcher picks on this CPU (AVX2 where it has it, unless DUET_SIMD=scalar).
void BM_FollowSessionStep(benchmark::State& state) {
  follow_session_step(state, detect_simd_level());
}
BENCHMARK(BM_FollowSessionStep)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->MinTime(3.0);

// The portable scalar/Eigen kernels, for the ratio in the same run.
void BM_FollowSessionStepScalar(benchmark::State& state) {
  follow_session_step(state, SimdLevel::kScalar);
}
BENCHMARK(BM_FollowSessionStepScalar)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->MinTime(3.0);

// Three points (issue 12): the head and hands of take 01.
void BM_FollowSessionStepHeadHands(benchmark::State& state) {
  follow_session_step(state, detect_simd_level(), InputPoints::kHeadHands);
}
BENCHMARK(BM_FollowSessionStepHeadHands)->Arg(0)->Unit(benchmark::kMicrosecond)->MinTime(3.0);

void BM_FeatureExtract(benchmark::State& state) {
  MotionLoadOptions load;
  load.frame_rate = 60.0;
  Result<LoadedMotion> input = load_motion({kSalsa + "/bvh/60/60_01_scaled.bvh"}, load);
  if (!input) {
    state.SkipWithError(input.error().message.c_str());
    return;
  }
  const Clip& clip = input.value().clip;
  FeatureSpec spec;
  spec.debiased_speeds = state.range(0) == 1;
  Result<FeatureExtractor> extractor =
      FeatureExtractor::create(clip.skeleton_ptr(), input.value().roles, spec);
  if (!extractor) {
    state.SkipWithError(extractor.error().message.c_str());
    return;
  }
  FeatureExtractor::Context context = extractor.value().make_context();
  std::vector<float> features(static_cast<std::size_t>(extractor.value().dimension()));
  int f = 0;
  double time_s = 0.0;
  for (auto _ : state) {
    extractor.value().extract(context, clip.translations_ls(f), clip.rotations_ls(f), time_s,
                              features);
    benchmark::DoNotOptimize(features.data());
    f = (f + 1) % clip.frame_count();
    time_s += 1.0 / 60.0;
  }
}
BENCHMARK(BM_FeatureExtract)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_DevicePointsToJoints(benchmark::State& state) {
  const DevicePointOffsets offsets = typical_headset_offsets();
  std::vector<Vec3> translations(kHeadHandsJointCount, Vec3(0.1, 1.5, -0.2));
  std::vector<Quat> rotations(kHeadHandsJointCount, Quat(0.9, 0.1, 0.3, 0.2).normalized());
  for (auto _ : state) {
    device_points_to_joints(offsets, translations, rotations);
    benchmark::DoNotOptimize(translations.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_DevicePointsToJoints)->Unit(benchmark::kNanosecond);

void BM_WristsOnUserBody(benchmark::State& state) {
  MotionLoadOptions load;
  load.frame_rate = 60.0;
  Result<LoadedMotion> dancer = load_motion({kSalsa + "/bvh/60/60_01_scaled.bvh"}, load);
  Result<LoadedMotion> user =
      state.range(0) == 0
          ? load_motion({kSalsa + "/bvh/60/60_01_scaled.bvh"}, load)
          : load_motion({kSalsa + "/asf-amc/60.asf", kSalsa + "/asf-amc/60_01.amc"}, load);
  if (!dancer || !user) {
    state.SkipWithError("salsa data not found");
    return;
  }
  SourceSkeleton user_skeleton;
  user_skeleton.skeleton = user.value().clip.skeleton_ptr();
  user_skeleton.roles = user.value().roles;
  Result<WristsOnUserBody> wrists = WristsOnUserBody::create({&dancer.value()}, user_skeleton);
  if (!wrists) {
    state.SkipWithError(wrists.error().message.c_str());
    return;
  }
  const int frames = dancer.value().clip.frame_count();
  double frame = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(wrists.value().wrist_difference_hs(0, frame));
    frame += 1.25;  // the playhead between frames
    if (frame >= frames - 1) frame = 0.0;
  }
}
BENCHMARK(BM_WristsOnUserBody)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace duet
