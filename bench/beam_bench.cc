// Per-frame cost of the follower at library sizes beyond the real one (issue 13): the exact step
// and the beam step on the salsa library (27,495 states) and on synthetic libraries of 100k and
// 1M states made from it (synthetic_library.h: time-warped, noisy copies of the real takes).
// The dancer performs the real takes (their features plus noise) and jumps to another take every
// 10 s. Each frame is timed: the counters give the median and the p99 per frame in microseconds
// (the beam's cost varies with the frame: a jump widens it, a fallback is a full step), the share
// of frames that took the full step, and the peak resident memory of the process (run one size
// alone, --benchmark_filter='/1000000', for the memory of that size: rss_mb is the process's
// resident memory while it runs; the real library's motion is not kept).
#include <benchmark/benchmark.h>
#include <immintrin.h>
#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <ctime>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "duet/features/feature_mirror.h"
#include "duet/follow/beam_follower.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/model_cache.h"
#include "duet/follow/synthetic_library.h"
#include "duet/live/duet_library.h"
#include "salsa_pairs.h"

namespace duet {
namespace {

using bench::kSalsa;
constexpr int kRealStates = 27495;

// The salsa library's model alone, and its features' mirror map: the library's motion is
// dropped (and its memory returned to the system), so that the resident memory measured is the
// follower's.
struct SalsaModel {
  TemplateModel model;
  std::vector<MirroredDim> mirror;
};
const SalsaModel* salsa() {
  static const std::optional<SalsaModel> salsa = []() -> std::optional<SalsaModel> {
    const std::vector<PairFiles> pairs = bench::salsa_pairs();
    LibraryOptions options;
    options.load.frame_rate = 60.0;
    std::optional<SalsaModel> copy;
    {
      Result<DuetLibrary> loaded = DuetLibrary::load(pairs, options);
      if (!loaded) return std::nullopt;
      Result<std::vector<MirroredDim>> mirror =
          feature_mirror(options.features, loaded.value().normalizer());
      if (!mirror) return std::nullopt;
      copy.emplace(SalsaModel{loaded.value().model(), std::move(mirror).value()});
    }
    malloc_trim(0);
    return copy;
  }();
  return salsa ? &*salsa : nullptr;
}

const TemplateModel* salsa_model() { return salsa() ? &salsa()->model : nullptr; }

// How the copies of a synthetic library are made (the second benchmark argument).
enum Copies {
  kTimeWarped = 0,  // time-warped, noisy copies of the real takes
  // Every second copy is also the mirror image of its take (salsa's basic steps alternate sides,
  // so a mirrored copy looks like its take half a step later: many more look-alike places).
  kMirrored = 1,
  // As kMirrored, after the real takes themselves (as `--grow-library` builds a live library).
  kMirroredAfterReal = 2,
};

// The library of `states` states; one kept at a time (a 1M-state model is 450 MB).
const TemplateModel* library_of(int states, int copies = kTimeWarped) {
  static std::unique_ptr<TemplateModel> cached;
  static int cached_copies = kTimeWarped;
  const TemplateModel* real = salsa_model();
  if (real == nullptr) return nullptr;
  if (states == real->num_states()) return real;
  if (!cached || cached->num_states() != states || cached_copies != copies) {
    cached.reset();
    SyntheticLibraryOptions options;
    options.num_states = states;
    if (copies != kTimeWarped) options.mirror = salsa()->mirror;
    options.keep_real_takes = copies == kMirroredAfterReal;
    Result<TemplateModel> model = synthesize_library(*real, options);
    if (!model) return nullptr;
    cached = std::make_unique<TemplateModel>(std::move(model).value());
    cached_copies = copies;
  }
  return cached.get();
}

// The real takes in turn, 10 s of each from a random frame, with noise on every feature.
std::vector<std::vector<float>> performance(const TemplateModel& real, int frames) {
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, 0.03f);
  std::vector<std::vector<float>> out;
  int take = 0, state = 0, left = 0;
  for (int f = 0; f < frames; ++f) {
    if (left == 0 || state + 1 >= real.take_end(take)) {
      take = (take + 5) % real.num_takes();
      const int length = real.take_end(take) - real.take_begin(take);
      state = real.take_begin(take) + static_cast<int>(rng() % static_cast<unsigned>(length / 2));
      left = 600;
    }
    std::vector<float> phi(static_cast<std::size_t>(real.num_dims()));
    for (int d = 0; d < real.num_dims(); ++d) {
      phi[static_cast<std::size_t>(d)] = real.features()(state, d) + noise(rng);
    }
    out.push_back(std::move(phi));
    ++state;
    --left;
  }
  return out;
}

// A field of /proc/self/status in MB: VmRSS (resident now), VmHWM (peak).
double status_mb(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field, 0) == 0) return std::stod(line.substr(field.size())) / 1024.0;
  }
  return 0.0;
}

double thread_cpu_us() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e6 + static_cast<double>(t.tv_nsec) * 1e-3;
}

double percentile(std::vector<double>& values, int percent) {
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, values.size() * static_cast<std::size_t>(percent) / 100)];
}

// Times every step, in wall-clock time and in the thread's CPU time (on a shared machine the
// wall clock also counts the time other processes held the core); reports median and p99.
template <class Step>
void timed_frames(benchmark::State& state, const TemplateModel& model, Step&& step) {
  const std::vector<std::vector<float>> inputs =
      performance(*salsa_model(), static_cast<int>(state.max_iterations));
  std::vector<double> wall_us, cpu_us;
  wall_us.reserve(inputs.size());
  cpu_us.reserve(inputs.size());
  std::size_t q = 0;
  for (auto _ : state) {
    const double cpu_start = thread_cpu_us();
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(step(inputs[q]));
    const auto stop = std::chrono::steady_clock::now();
    cpu_us.push_back(thread_cpu_us() - cpu_start);
    wall_us.push_back(std::chrono::duration<double, std::micro>(stop - start).count());
    q = (q + 1) % inputs.size();
  }
  state.counters["states"] = model.num_states();
  state.counters["median_us"] = percentile(wall_us, 50);
  state.counters["p99_us"] = percentile(wall_us, 99);
  state.counters["cpu_median_us"] = percentile(cpu_us, 50);
  state.counters["cpu_p99_us"] = percentile(cpu_us, 99);
  state.counters["ns_per_state"] = 1000.0 * state.counters["cpu_median_us"] / model.num_states();
  state.counters["rss_mb"] = status_mb("VmRSS:");
}

void BM_ExactStepAtScale(benchmark::State& state) {
  const TemplateModel* model = library_of(static_cast<int>(state.range(0)));
  if (model == nullptr) {
    state.SkipWithError("salsa data not found");
    return;
  }
  HmmFollower hmm = HmmFollower::create(*model, {}).value();
  timed_frames(state, *model,
               [&](const std::vector<float>& phi) { return hmm.step(phi, 1.0 / 60); });
}
BENCHMARK(BM_ExactStepAtScale)
    ->Arg(kRealStates)->Iterations(3000)
    ->Arg(100000)->Iterations(1000)
    ->Arg(1000000)->Iterations(200)
    ->Unit(benchmark::kMicrosecond);

// Arguments: states, and the copies (enum Copies).
void BM_BeamStepAtScale(benchmark::State& state) {
  const TemplateModel* model =
      library_of(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  if (model == nullptr) {
    state.SkipWithError("salsa data not found");
    return;
  }
  BeamFollower beam = BeamFollower::create(*model, {}).value();
  std::vector<double> beam_states;
  beam_states.reserve(static_cast<std::size_t>(state.max_iterations));
  timed_frames(state, *model, [&](const std::vector<float>& phi) {
    const FollowResult result = beam.step(phi, 1.0 / 60);
    beam_states.push_back(beam.context().beam_size());
    return result;
  });
  state.counters["beam_p99"] = percentile(beam_states, 99);
  state.counters["beam_median"] = percentile(beam_states, 50);
  state.counters["full_step_pct"] =
      100.0 * static_cast<double>(beam.context().full_steps()) /
      static_cast<double>(std::max(1LL, beam.context().frames()));
  state.counters["index_mb"] = static_cast<double>(beam.forward().index().memory_bytes()) / 1e6;
}
BENCHMARK(BM_BeamStepAtScale)
    ->Args({kRealStates, 0})
    ->Args({100000, 0})
    ->Args({1000000, 0})
    ->Args({100000, kMirrored})
    ->Args({1000000, kMirrored})
    ->Args({100000, kMirroredAfterReal})
    ->Args({1000000, kMirroredAfterReal})
    ->Iterations(6000)
    ->Unit(benchmark::kMicrosecond);

// Input no part of the library explains (a user standing about, another dance): the performance
// above moved half a standard deviation off on every feature, so every frame is lost, for 10 s.
// The beam cannot settle "lost" from its candidates (every state within the lost distance must
// be ruled out, and the 8-dimensional bound is too loose to): such frames take the full step for
// the first BeamParams::lost_spell_before_s (2 s), then once per lost_full_step_s (0.5 s). The
// counters show what a lost user costs at each size (docs/follower.md "Beam mode"): the median
// is a frame of the spell past its first 2 s, the mean counts the 2 s.
void BM_BeamStepWhileLostAtScale(benchmark::State& state) {
  const TemplateModel* model = library_of(static_cast<int>(state.range(0)));
  if (model == nullptr) {
    state.SkipWithError("salsa data not found");
    return;
  }
  BeamFollower beam = BeamFollower::create(*model, {}).value();
  std::vector<std::vector<float>> inputs =
      performance(*salsa_model(), static_cast<int>(state.max_iterations));
  for (std::vector<float>& phi : inputs) {
    for (float& v : phi) v += 0.5f;
  }
  std::vector<double> cpu_us;
  cpu_us.reserve(inputs.size());
  long long lost = 0;
  std::size_t q = 0;
  for (auto _ : state) {
    const double cpu_start = thread_cpu_us();
    const FollowResult result = beam.step(inputs[q], 1.0 / 60);
    cpu_us.push_back(thread_cpu_us() - cpu_start);
    lost += result.lost ? 1 : 0;
    q = (q + 1) % inputs.size();
  }
  state.counters["states"] = model->num_states();
  double total_us = 0.0;
  for (const double us : cpu_us) total_us += us;
  state.counters["cpu_mean_us"] =
      total_us / static_cast<double>(std::max<std::size_t>(1, cpu_us.size()));
  state.counters["cpu_median_us"] = percentile(cpu_us, 50);
  state.counters["cpu_p99_us"] = percentile(cpu_us, 99);
  state.counters["lost_pct"] = 100.0 * static_cast<double>(lost) /
                               static_cast<double>(std::max<std::size_t>(1, cpu_us.size()));
  state.counters["full_step_pct"] = 100.0 * static_cast<double>(beam.context().full_steps()) /
                                    static_cast<double>(std::max(1LL, beam.context().frames()));
}
BENCHMARK(BM_BeamStepWhileLostAtScale)
    ->Arg(kRealStates)
    ->Iterations(2000)
    ->Arg(100000)
    ->Iterations(500)
    ->Arg(1000000)
    ->Iterations(600)
    ->Unit(benchmark::kMicrosecond);

// The memory floor of the exact step: reading the features once per frame. An AVX2 sum (four
// accumulators) over a buffer the size of the features at 27,495 states (5.5 MB, in L3) and at 1M
// states (200 MB, from DRAM); bytes_per_second gives the floor in ns per state (200 bytes at
// D = 50). Skipped on a CPU without AVX2.
__attribute__((target("avx2"))) float sum_avx2(const float* data, std::size_t floats) {
  __m256 a = _mm256_setzero_ps(), b = a, c = a, d = a;
  for (std::size_t i = 0; i + 32 <= floats; i += 32) {
    a = _mm256_add_ps(a, _mm256_loadu_ps(data + i));
    b = _mm256_add_ps(b, _mm256_loadu_ps(data + i + 8));
    c = _mm256_add_ps(c, _mm256_loadu_ps(data + i + 16));
    d = _mm256_add_ps(d, _mm256_loadu_ps(data + i + 24));
  }
  alignas(32) float out[8];
  _mm256_store_ps(out, _mm256_add_ps(_mm256_add_ps(a, b), _mm256_add_ps(c, d)));
  return out[0] + out[1] + out[2] + out[3] + out[4] + out[5] + out[6] + out[7];
}

void BM_ReadBandwidth(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx2")) {
    state.SkipWithError("no AVX2 on this CPU");
    return;
  }
  const auto floats = static_cast<std::size_t>(state.range(0)) / sizeof(float);
  std::vector<float> buffer(floats, 1.0f);
  for (auto _ : state) benchmark::DoNotOptimize(sum_avx2(buffer.data(), floats));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_ReadBandwidth)->Arg(27495 * 200)->Arg(1000000 * 200)->Unit(benchmark::kMicrosecond);

// Would the second core pay (issue 13)? The same read split between this thread and a helper
// thread that sleeps between frames (std::atomic wait/notify, as a live loop's helper would:
// spinning would take the core the server's network and recorder threads run on). Each frame is
// timed, wake-up included: median and p99 per frame, against BM_ReadBandwidth's one thread.
void BM_ReadBandwidthTwoThreads(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx2")) {
    state.SkipWithError("no AVX2 on this CPU");
    return;
  }
  const auto floats = static_cast<std::size_t>(state.range(0)) / sizeof(float);
  const std::size_t half = floats / 2;
  std::vector<float> buffer(floats, 1.0f);
  std::atomic<int> frame{0}, finished{0};
  std::atomic<bool> quit{false};
  std::thread helper([&] {
    int seen = 0;
    while (true) {
      frame.wait(seen, std::memory_order_acquire);
      if (quit.load()) return;
      seen = frame.load(std::memory_order_acquire);
      benchmark::DoNotOptimize(sum_avx2(buffer.data() + half, floats - half));
      finished.store(seen, std::memory_order_release);
    }
  });
  std::vector<double> frame_us;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const int f = frame.fetch_add(1, std::memory_order_release) + 1;
    frame.notify_one();
    benchmark::DoNotOptimize(sum_avx2(buffer.data(), half));
    while (finished.load(std::memory_order_acquire) != f) {
    }
    frame_us.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
            .count());
  }
  quit.store(true);
  frame.fetch_add(1);
  frame.notify_one();
  helper.join();
  state.counters["median_us"] = percentile(frame_us, 50);
  state.counters["p99_us"] = percentile(frame_us, 99);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_ReadBandwidthTwoThreads)
    ->Arg(27495 * 200)
    ->Arg(1000000 * 200)
    ->Iterations(200)
    ->Unit(benchmark::kMicrosecond);

// Start-up from the model cache file: map it, check it, copy the features into the model (which
// blocks them for the AVX2 kernel), load the jump candidate index and create the beam follower.
// The cache is written once beforehand (in the temporary directory, removed afterwards).
void BM_StartUpFromCache(benchmark::State& state) {
  const TemplateModel* model = library_of(static_cast<int>(state.range(0)));
  if (model == nullptr) {
    state.SkipWithError("salsa data not found");
    return;
  }
  const std::string path =
      (std::filesystem::temp_directory_path() / "duet_beam_bench.model").string();
  {
    const JumpCandidateIndex index = JumpCandidateIndex::build(*model).value();
    if (!write_model_cache(path, *model, index, 1).ok()) {
      state.SkipWithError("cannot write the cache");
      return;
    }
  }
  for (auto _ : state) {
    Result<CachedModel> cached = read_model_cache(path, 1);
    if (!cached) {
      state.SkipWithError(cached.error().message.c_str());
      break;
    }
    CachedModel& c = cached.value();
    Result<BeamFollower> beam = BeamFollower::create(
        c.model, {}, {}, std::make_shared<const JumpCandidateIndex>(std::move(c.index)));
    benchmark::DoNotOptimize(beam.ok());
  }
  state.counters["cache_mb"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  std::filesystem::remove(path);
}
BENCHMARK(BM_StartUpFromCache)->Arg(1000000)->Iterations(3)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace duet
