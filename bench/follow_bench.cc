// Per-frame cost of the follower's forward step. The O(M) step of eq. 11 grows linearly with the
// number of template states M (D = 60 features); the naive O(M^2) forward of eq. 10 is shown
// alongside on smaller M. 27495 states is the size of a full salsa library. Budget: < 1 ms per
// frame at 27k states on one thread.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "duet/features/feature_spec.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/naive_hmm.h"
#include "duet/follow/nearest_neighbour.h"
#include "duet/follow/online_dtw.h"
#include "duet/follow/simd.h"
#include "follow/forward_common.h"

namespace duet {
namespace {

constexpr int kDims = 60;
constexpr int kQueries = 64;

TemplateModel random_model(int states, int dims = kDims) {
  std::mt19937 rng(static_cast<unsigned>(states));
  std::normal_distribution<float> normal(0.0f, 1.0f);
  FeatureMatrix f(states, dims);
  for (Eigen::Index i = 0; i < f.size(); ++i) f.data()[i] = normal(rng);
  // A library of takes of about 2000 frames, like the salsa takes.
  std::vector<int> starts;
  for (int s = 0; s < states; s += 2000) starts.push_back(s);
  // The last 8 dimensions are velocities, as in the real features: the HMM caps their distance.
  TemplateModel model = std::move(TemplateModel::build(std::move(f), starts, 60.0, 8)).value();
  // And the full body's limbs, whose share it caps too (FeatureSpec::limb_dims).
  if (dims - 8 >= FeatureSpec{}.posture_dims()) {
    if (!model.set_limbs(FeatureSpec{}.limb_dims())) std::abort();
  }
  return model;
}

// Input frames: template frames plus noise, so the emission is realistic.
std::vector<std::vector<float>> queries(const TemplateModel& model) {
  std::mt19937 rng(7);
  std::normal_distribution<float> normal(0.0f, 0.2f);
  std::vector<std::vector<float>> out;
  for (int q = 0; q < kQueries; ++q) {
    const int i = (q * 37) % model.num_states();
    std::vector<float> phi(static_cast<std::size_t>(model.num_dims()));
    for (int d = 0; d < model.num_dims(); ++d)
      phi[static_cast<std::size_t>(d)] = model.features()(i, d) + normal(rng);
    out.push_back(std::move(phi));
  }
  return out;
}

void run(benchmark::State& state, Tracker& tracker, const TemplateModel& model, double dt_s) {
  const auto inputs = queries(model);
  std::size_t q = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(tracker.step(inputs[q], dt_s));
    q = (q + 1) % inputs.size();
  }
  state.SetComplexityN(model.num_states());
  state.counters["states"] = model.num_states();
}

void BM_ForwardStep(benchmark::State& state) {
  const TemplateModel model = random_model(static_cast<int>(state.range(0)));
  HmmFollower hmm = HmmFollower::create(model, {}).value();
  run(state, hmm, model, 1.0 / 60);
}
BENCHMARK(BM_ForwardStep)
    ->Arg(1000)
    ->Arg(4000)
    ->Arg(16000)
    ->Arg(27495)
    ->Unit(benchmark::kMicrosecond)
    ->Complexity(benchmark::oN);

// A 30 Hz sensor: two transitions per frame, one emission.
void BM_ForwardStep30Hz(benchmark::State& state) {
  const TemplateModel model = random_model(static_cast<int>(state.range(0)));
  HmmFollower hmm = HmmFollower::create(model, {}).value();
  run(state, hmm, model, 1.0 / 30);
}
BENCHMARK(BM_ForwardStep30Hz)->Arg(27495)->Unit(benchmark::kMicrosecond);

// Every frame after a 1 s tracking loss: 60 transitions, one emission (the cost of the first frame
// after such a gap; FollowParams::max_steps_per_frame).
void BM_ForwardStepAfterGap(benchmark::State& state) {
  const TemplateModel model = random_model(static_cast<int>(state.range(0)));
  HmmFollower hmm = HmmFollower::create(model, {}).value();
  run(state, hmm, model, 1.0);
}
BENCHMARK(BM_ForwardStepAfterGap)->Arg(27495)->Unit(benchmark::kMicrosecond);

void BM_NaiveForwardStep(benchmark::State& state) {
  const TemplateModel model = random_model(static_cast<int>(state.range(0)));
  NaiveHmmFollower naive = NaiveHmmFollower::create(model, {}).value();
  run(state, naive, model, 1.0 / 60);
}
BENCHMARK(BM_NaiveForwardStep)
    ->Arg(250)
    ->Arg(500)
    ->Arg(1000)
    ->Arg(2000)
    ->Unit(benchmark::kMicrosecond)
    ->Complexity(benchmark::oNSquared);

void BM_NearestNeighbour(benchmark::State& state) {
  const TemplateModel model = random_model(static_cast<int>(state.range(0)));
  NearestNeighbourTracker nn = NearestNeighbourTracker::create(model, {}).value();
  run(state, nn, model, 1.0 / 60);
}
BENCHMARK(BM_NearestNeighbour)->Arg(27495)->Unit(benchmark::kMicrosecond);

void BM_OnlineDtw(benchmark::State& state) {
  const TemplateModel model = random_model(static_cast<int>(state.range(0)));
  OnlineDtwTracker dtw = OnlineDtwTracker::create(model, {}).value();
  run(state, dtw, model, 1.0 / 60);
}
BENCHMARK(BM_OnlineDtw)->Arg(27495)->Unit(benchmark::kMicrosecond);

// ---------------------------------------------------------------------------------------------
// The step's kernels on each instruction set in one run (src/follow/kernels_avx2.h, issue 13):
// 27495 states and D = 50 like the salsa library. per_state is the time per template state.

constexpr int kLibraryStates = 27495;
constexpr int kLibraryDims = 50;

// Selects level for one benchmark; false (and the benchmark skipped) when the CPU lacks it.
bool use_level(benchmark::State& state, SimdLevel level) {
  if (set_simd_level(level)) return true;
  state.SkipWithError("this CPU cannot run this instruction set");
  return false;
}

void count_states(benchmark::State& state, int states) {
  state.counters["states"] = states;
  // Seconds per state (printed with its SI prefix, e.g. 2.1ns).
  state.counters["per_state"] = benchmark::Counter(
      states, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_EmissionDistances(benchmark::State& state, SimdLevel level) {
  if (!use_level(state, level)) return;
  const TemplateModel model = random_model(kLibraryStates, kLibraryDims);
  const auto inputs = queries(model);
  std::vector<float> out(static_cast<std::size_t>(model.num_states()));
  const follow_detail::DistanceCaps caps = follow_detail::emission_caps(FollowParams{});
  std::size_t q = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        follow_detail::emission_distances(model, inputs[q].data(), caps, out.data()));
    benchmark::ClobberMemory();
    q = (q + 1) % inputs.size();
  }
  count_states(state, model.num_states());
  set_simd_level(detect_simd_level());
}
BENCHMARK_CAPTURE(BM_EmissionDistances, scalar, SimdLevel::kScalar)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_EmissionDistances, avx2, SimdLevel::kAvx2)->Unit(benchmark::kMicrosecond);

// The exp pass of eq. 11 (weigh_and_normalise) on the distances of a real-looking query.
void BM_WeighAndNormalise(benchmark::State& state, SimdLevel level) {
  if (!use_level(state, level)) return;
  const TemplateModel model = random_model(kLibraryStates, kLibraryDims);
  const int m = model.num_states();
  const auto size = static_cast<std::size_t>(m);
  std::vector<float> distance_sq(size), predicted(size + 1, 1.0f / static_cast<float>(m + 1));
  std::vector<float> out(size + 1);
  // The dancer exactly on a template frame: the common, fast path (a query far from every
  // template would, with uniform predicted mass, take the rare rescaling path instead).
  const Eigen::RowVectorXf on_template = model.features().row(m / 3);
  const float best = follow_detail::emission_distances(model, on_template.data(),
                                                       follow_detail::emission_caps(FollowParams{}),
                                                       distance_sq.data())
                         .bounded;
  // The default parameters, as HmmForward::create derives them.
  const FollowParams params;
  const float inv_two_sigma_sq = 1.0f / (2.0f * params.emission_sigma * params.emission_sigma);
  const float log_b_pause = -params.pause_distance_per_dim * kLibraryDims * inv_two_sigma_sq;
  const follow_detail::ScopedFlushDenormals flush_denormals;  // as in HmmForward::step
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        follow_detail::weigh_and_normalise(predicted.data(), distance_sq.data(), best,
                                           inv_two_sigma_sq, m, log_b_pause, true, out.data()));
    benchmark::ClobberMemory();
  }
  count_states(state, m);
  set_simd_level(detect_simd_level());
}
BENCHMARK_CAPTURE(BM_WeighAndNormalise, scalar, SimdLevel::kScalar)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_WeighAndNormalise, avx2, SimdLevel::kAvx2)->Unit(benchmark::kMicrosecond);

// The whole forward step (BM_ForwardStep) on each instruction set, D = 50.
void BM_ForwardStepSimd(benchmark::State& state, SimdLevel level) {
  if (!use_level(state, level)) return;
  const TemplateModel model = random_model(kLibraryStates, kLibraryDims);
  HmmFollower hmm = HmmFollower::create(model, {}).value();
  run(state, hmm, model, 1.0 / 60);
  count_states(state, model.num_states());
  set_simd_level(detect_simd_level());
}
BENCHMARK_CAPTURE(BM_ForwardStepSimd, scalar, SimdLevel::kScalar)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ForwardStepSimd, avx2, SimdLevel::kAvx2)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace duet
