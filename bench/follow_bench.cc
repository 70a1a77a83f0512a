// Per-frame cost of the follower's forward step. The O(M) step of eq. 11 grows linearly with the
// number of template states M (D = 60 features); the naive O(M^2) forward of eq. 10 is shown
// alongside on smaller M. 27495 states is the size of a full salsa library. Budget: < 1 ms per
// frame at 27k states on one thread.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "duet/follow/hmm_follower.h"
#include "duet/follow/naive_hmm.h"
#include "duet/follow/nearest_neighbour.h"
#include "duet/follow/online_dtw.h"

namespace duet {
namespace {

constexpr int kDims = 60;
constexpr int kQueries = 64;

TemplateModel random_model(int states) {
  std::mt19937 rng(static_cast<unsigned>(states));
  std::normal_distribution<float> normal(0.0f, 1.0f);
  FeatureMatrix f(states, kDims);
  for (Eigen::Index i = 0; i < f.size(); ++i) f.data()[i] = normal(rng);
  // A library of takes of about 2000 frames, like the salsa takes.
  std::vector<int> starts;
  for (int s = 0; s < states; s += 2000) starts.push_back(s);
  // The last 8 dimensions are velocities, as in the real features: the HMM caps their distance.
  return std::move(TemplateModel::build(std::move(f), starts, 60.0, 8)).value();
}

// Input frames: template frames plus noise, so the emission is realistic.
std::vector<std::vector<float>> queries(const TemplateModel& model) {
  std::mt19937 rng(7);
  std::normal_distribution<float> normal(0.0f, 0.2f);
  std::vector<std::vector<float>> out;
  for (int q = 0; q < kQueries; ++q) {
    const int i = (q * 37) % model.num_states();
    std::vector<float> phi(kDims);
    for (int d = 0; d < kDims; ++d)
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

}  // namespace
}  // namespace duet
