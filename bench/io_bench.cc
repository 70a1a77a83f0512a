// I/O benchmarks on a real take: parsing the CMU salsa BVH 60_01 (2.9 MB, 2242 frames, 132
// channels, 57 joints with End Sites) from memory and from file, writing it, and forward
// kinematics of the whole take. Cost scales with frames x channels (parsing, writing) and
// frames x joints (forward kinematics); the counters give the per-frame cost.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "duet/io/asf_amc.h"
#include "duet/io/bvh.h"
#include "duet/motion/forward_kinematics.h"

namespace {

const std::string kTake = std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/60/60_01_scaled.bvh";

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool load(benchmark::State& state, duet::Clip& clip) {
  duet::Result<duet::Clip> result = duet::read_bvh(kTake);
  if (!result) {
    state.SkipWithError(result.error().message.c_str());
    return false;
  }
  clip = std::move(result).value();
  return true;
}

void per_frame_counters(benchmark::State& state, int frames) {
  state.counters["frames"] = frames;
  state.counters["per_frame"] = benchmark::Counter(
      static_cast<double>(frames),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_ParseBvhFromMemory(benchmark::State& state) {
  const std::string text = slurp(kTake);
  if (text.empty()) {
    state.SkipWithError(("cannot read " + kTake).c_str());
    return;
  }
  int frames = 0;
  for (auto _ : state) {
    duet::Result<duet::Clip> clip = duet::parse_bvh(text, kTake);
    if (!clip) {
      state.SkipWithError(clip.error().message.c_str());
      return;
    }
    frames = clip.value().frame_count();
    benchmark::DoNotOptimize(clip);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
  per_frame_counters(state, frames);
}
BENCHMARK(BM_ParseBvhFromMemory)->Unit(benchmark::kMillisecond);

void BM_ReadBvhFromFile(benchmark::State& state) {
  int frames = 0;
  for (auto _ : state) {
    duet::Result<duet::Clip> clip = duet::read_bvh(kTake);
    if (!clip) {
      state.SkipWithError(clip.error().message.c_str());
      return;
    }
    frames = clip.value().frame_count();
    benchmark::DoNotOptimize(clip);
  }
  per_frame_counters(state, frames);
}
BENCHMARK(BM_ReadBvhFromFile)->Unit(benchmark::kMillisecond);

// The CMU original of the same take: 60.asf + 60_01.amc (1.8 MB).
void BM_ReadAsfAmcFromFile(benchmark::State& state) {
  const std::string dir = std::string(DUET_DATA_DIR) + "/cmu-salsa/asf-amc/";
  int frames = 0;
  for (auto _ : state) {
    duet::Result<duet::Clip> clip = duet::read_asf_amc(dir + "60.asf", dir + "60_01.amc");
    if (!clip) {
      state.SkipWithError(clip.error().message.c_str());
      return;
    }
    frames = clip.value().frame_count();
    benchmark::DoNotOptimize(clip);
  }
  per_frame_counters(state, frames);
}
BENCHMARK(BM_ReadAsfAmcFromFile)->Unit(benchmark::kMillisecond);

void BM_FormatBvh(benchmark::State& state) {
  duet::Clip clip;
  if (!load(state, clip)) return;
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string text = duet::format_bvh(clip);
    bytes = text.size();
    benchmark::DoNotOptimize(text.data());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes));
  per_frame_counters(state, clip.frame_count());
}
BENCHMARK(BM_FormatBvh)->Unit(benchmark::kMillisecond);

// World positions of every joint (End Sites included) at every frame of the take.
void BM_ForwardKinematicsFullTake(benchmark::State& state) {
  duet::Clip clip;
  if (!load(state, clip)) return;
  for (auto _ : state) {
    std::vector<duet::Vec3> positions = duet::world_positions(clip);
    benchmark::DoNotOptimize(positions.data());
  }
  per_frame_counters(state, clip.frame_count());
  state.counters["joints"] = clip.joint_count();
}
BENCHMARK(BM_ForwardKinematicsFullTake)->Unit(benchmark::kMillisecond);

// The per-frame path alone: caller-owned buffers, nothing allocated.
void BM_ForwardKinematicsOneFrame(benchmark::State& state) {
  duet::Clip clip;
  if (!load(state, clip)) return;
  const auto n = static_cast<std::size_t>(clip.joint_count());
  std::vector<duet::Vec3> positions(n);
  std::vector<duet::Quat> rotations(n);
  int frame = 0;
  for (auto _ : state) {
    duet::forward_kinematics(clip.skeleton(), clip.translations_ls(frame), clip.rotations_ls(frame),
                             positions, rotations);
    benchmark::DoNotOptimize(positions.data());
    frame = frame + 1 == clip.frame_count() ? 0 : frame + 1;
  }
  state.counters["joints"] = clip.joint_count();
}
BENCHMARK(BM_ForwardKinematicsOneFrame);

}  // namespace
