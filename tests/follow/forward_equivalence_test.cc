// The O(M) forward step of eq. 11 against the O(M^2) forward of eq. 10 with the full transition
// matrix: same alpha (within float tolerance), same estimates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "duet/follow/hmm_follower.h"
#include "duet/follow/naive_hmm.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

// The dense matrix is a proper transition matrix and agrees with HmmForward's rows.
void expect_same_transitions(const TemplateModel& model, const FollowParams& params) {
  const HmmForward fast = HmmForward::create(model, params).value();
  const NaiveHmmFollower naive = NaiveHmmFollower::create(model, params).value();
  const int pause = model.num_states();
  for (int j = 0; j <= pause; ++j) {
    double sum = 0.0;
    for (int i = 0; i <= pause; ++i) sum += naive.transition(j, i);
    EXPECT_NEAR(sum, 1.0, 1e-5) << "row " << j;
  }
  for (int j = 0; j < pause; ++j) {
    const HmmForward::Row row = fast.row(j);
    for (int d = 0; d <= 2; ++d) {
      const float dense = j + d < pause ? naive.transition(j, j + d) : 0.0f;
      EXPECT_NEAR(row.band[d], dense, 1e-6f) << j << " +" << d;
    }
    EXPECT_NEAR(row.leave, naive.transition(j, pause), 1e-6f) << j;
  }
  if (params.jump_enabled) {
    EXPECT_NEAR(fast.pause_stay(), naive.transition(pause, pause), 1e-6f);
    for (int i = 0; i < pause; ++i) EXPECT_NEAR(fast.resume(i), naive.transition(pause, i), 1e-7f);
  }
}

struct Scenario {
  const char* name;
  std::vector<int> takes;
  FollowParams params;
  int velocity_dims = 0;     // trailing dimensions whose distance is capped
  bool tempo_moves = false;  // the replay must move the tempo-centred band away from 1
};

std::vector<Scenario> scenarios() {
  std::vector<Scenario> out;
  out.push_back({"default, one take", {240}, FollowParams{}});
  // Short takes exercise every boundary case of the band (1, 2 and 3 frames).
  out.push_back({"default, library", {90, 1, 2, 3, 60, 84}, FollowParams{}});
  out.push_back({"paper", {120, 120}, FollowParams::paper()});
  // The defaults' pause distance is below this replay's noise (the pause state wins and nothing
  // is a band move); a larger one lets the band follow the replay's 0.6x-1.6x tempo.
  FollowParams tempo;
  tempo.pause_distance_per_dim = 0.05f;
  tempo.lost_distance_per_dim = 1.0f;
  out.push_back({"tempo-centred band", {200, 90}, tempo, 0, true});
  FollowParams fixed_band;
  fixed_band.tempo_adaptive = false;
  out.push_back({"fixed band", {120, 60}, fixed_band});
  // The synthetic features are about unit size per dimension: a cap of 0.5 bites often.
  FollowParams capped;
  capped.velocity_distance_cap = 0.5f;
  out.push_back({"velocity cap", {150, 70}, capped, 4});
  out.push_back({"left to right", {100, 3, 1, 2, 90}, FollowParams::left_to_right()});
  FollowParams resume;
  resume.resume_weights.resize(200);
  for (std::size_t i = 0; i < resume.resume_weights.size(); ++i) {
    resume.resume_weights[i] = 1.0f + static_cast<float>(i % 7);
  }
  out.push_back({"non-uniform resume", {150, 50}, resume});
  FollowParams sharp;
  sharp.emission_sigma = 0.3f;  // exercises the underflow fallback of the emission
  sharp.leave_prob = 0.01f;
  out.push_back({"sharp emission", {150, 100}, sharp});
  return out;
}

TEST(ForwardEquivalence, TransitionMatricesAgree) {
  for (const Scenario& s : scenarios()) {
    SCOPED_TRACE(s.name);
    const TemplateModel model = test::make_model(s.takes, 12, 5, 60.0, s.velocity_dims);
    expect_same_transitions(model, s.params);
  }
}

TEST(ForwardEquivalence, SameAlphaAndEstimatesOverJumpsRatesAndMissingFrames) {
  for (const Scenario& scenario : scenarios()) {
    SCOPED_TRACE(scenario.name);
    // The naive forward is the paper's model with fixed levels: the O(M) step is compared with
    // the pause level and the emission's scale fixed, the input unfiltered, no jump hold and the
    // raw window mass (the noise scaling is tested on its own, sensor_noise_test.cc and
    // noise_filter_test.cc; it changes no part of the forward but the emissions and the input).
    // Nor has it the outlier gate (tested in hmm_follower_test.cc).
    Scenario s = scenario;
    s.params.gate_outliers = false;
    s.params.pause_noise_factor = 0.0f;
    s.params.emission_noise_factor = 0.0f;
    s.params.noise_filter_density = 0.0f;
    s.params.noisy_jump_hold_s = 0.0f;
    s.params.unexplained_jump_hold_s = 0.0f;
    s.params.calibrate_confidence = false;
    const TemplateModel model = test::make_model(s.takes, 16, 11, 60.0, s.velocity_dims);
    HmmFollower fast = HmmFollower::create(model, s.params).value();
    NaiveHmmFollower naive = NaiveHmmFollower::create(model, s.params).value();
    std::mt19937 rng(42);
    std::uniform_int_distribution<int> anywhere(0, model.num_states() - 1);
    std::uniform_real_distribution<double> speed(0.6, 1.6);
    const double dts[] = {1.0 / 60, 1.0 / 60, 1.0 / 30, 0.0, 0.1, 1.0 / 120};

    double position = anywhere(rng);
    int agree = 0;
    float tempo_range = 0.0f;
    const int frames = 400;
    for (int t = 0; t < frames; ++t) {
      if (t % 60 == 59) position = anywhere(rng);  // jump elsewhere (another take, too)
      const double dt = dts[t % 6];
      std::vector<float> phi = test::features_at(model, position);
      test::add_noise(phi, 0.1f, rng);
      // A missing frame (the naive forward takes a partly observed one as missing too; the O(M)
      // step carries it: robustness_test.cc).
      if (t % 97 == 13) std::ranges::fill(phi, std::numeric_limits<float>::quiet_NaN());
      if (t % 131 == 7) std::fill(phi.begin(), phi.end(), 40.0f);          // far from all
      position += speed(rng) * std::max(1.0, std::round(dt * 60.0));
      if (position >= model.num_states() - 1) position = 0;

      const FollowResult a = fast.step(phi, dt);
      const FollowResult b = naive.step(phi, dt);
      const auto alpha_fast = fast.context().alpha();
      const auto alpha_naive = naive.alpha();
      ASSERT_EQ(alpha_fast.size(), alpha_naive.size());
      float worst = 0.0f;
      for (std::size_t i = 0; i < alpha_fast.size(); ++i) {
        worst = std::max(worst, std::abs(alpha_fast[i] - alpha_naive[i]));
      }
      ASSERT_LT(worst, 2e-5f) << "frame " << t;
      EXPECT_EQ(a.missing, b.missing);
      EXPECT_EQ(a.steps, b.steps);
      EXPECT_EQ(a.in_pause, b.in_pause);
      EXPECT_NEAR(a.log_likelihood, b.log_likelihood, 1e-3 + 1e-5 * std::abs(a.log_likelihood));
      EXPECT_NEAR(a.confidence, b.confidence, 1e-4f);
      EXPECT_NEAR(a.tempo, b.tempo, 1e-4f);
      // The band's own tempo (per template-rate step; the reported one also counts the input's
      // rate, which the 1/120 s frames raise above 1).
      tempo_range = std::max(tempo_range, std::abs(fast.context().tempo() - 1.0f));
      // Equal estimates, unless two states tie within float noise.
      if (a.state == b.state) {
        ++agree;
      } else {
        EXPECT_NEAR(alpha_fast[static_cast<std::size_t>(a.state)],
                    alpha_fast[static_cast<std::size_t>(b.state)], 1e-5f)
            << "frame " << t;
      }
    }
    EXPECT_GE(agree, frames - 2);
    // The tempo-centred band was exercised (the replay runs at 0.6x-1.6x), or is off.
    if (s.tempo_moves) {
      EXPECT_GT(tempo_range, 0.05f);
    }
    if (!s.params.tempo_adaptive) {
      EXPECT_EQ(tempo_range, 0.0f);
    }
  }
}

}  // namespace
}  // namespace duet
