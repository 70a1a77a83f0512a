// The AVX2+FMA kernels against the portable scalar/Eigen path they replace at run time: the
// emission distances (eq. 7), the exp, the argmax (eq. 8-9) and the posterior of whole forward
// steps (eq. 11). Where the CPU has no AVX2 the dispatcher must have chosen the scalar path.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "duet/features/feature_spec.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/simd.h"
#include "follow/forward_common.h"
#include "follow/kernels_avx2.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

bool cpu_has_avx2() { return cpu_supports(SimdLevel::kAvx2); }

// Puts the active level back after a test that switches it.
class RestoreSimdLevel {
 public:
  ~RestoreSimdLevel() { set_simd_level(saved_); }

 private:
  SimdLevel saved_ = simd_level();
};

// Template frames plus noise, as a dancer's input would be.
std::vector<float> query_near(const TemplateModel& model, int state, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 0.2f);
  std::vector<float> phi(static_cast<std::size_t>(model.num_dims()));
  for (int d = 0; d < model.num_dims(); ++d) {
    phi[static_cast<std::size_t>(d)] = model.features()(state, d) + noise(rng);
  }
  return phi;
}

TEST(SimdDispatch, DuetSimdScalarForcesTheScalarPathAndAvx2IsChosenWhereTheCpuHasIt) {
  const RestoreSimdLevel restore;
  const char* before = std::getenv("DUET_SIMD");
  const std::string saved = before != nullptr ? before : "";
  ::setenv("DUET_SIMD", "scalar", 1);
  EXPECT_EQ(detect_simd_level(), SimdLevel::kScalar);
  ::unsetenv("DUET_SIMD");
  EXPECT_EQ(detect_simd_level(), cpu_has_avx2() ? SimdLevel::kAvx2 : SimdLevel::kScalar);
  if (before != nullptr) ::setenv("DUET_SIMD", saved.c_str(), 1);

  EXPECT_TRUE(set_simd_level(SimdLevel::kScalar));
  EXPECT_EQ(simd_level(), SimdLevel::kScalar);
  EXPECT_EQ(set_simd_level(SimdLevel::kAvx2), cpu_has_avx2());
  EXPECT_EQ(simd_level(), cpu_has_avx2() ? SimdLevel::kAvx2 : SimdLevel::kScalar);
  std::printf("this CPU: %s\n", to_string(detect_simd_level()));
}

// Distances through the dispatcher at both levels, within 1e-4 relative, same minimum.
void expect_same_distances(const TemplateModel& model, float velocity_cap,
                           float limb_ratio = std::numeric_limits<float>::infinity()) {
  const follow_detail::DistanceCaps caps{velocity_cap, limb_ratio, 0.05f};
  const RestoreSimdLevel restore;
  const auto size = static_cast<std::size_t>(model.num_states());
  std::vector<float> scalar(size), fast(size);
  for (const int state : {0, model.num_states() / 2, model.num_states() - 1}) {
    const std::vector<float> phi = query_near(model, state, static_cast<unsigned>(state));
    ASSERT_TRUE(set_simd_level(SimdLevel::kScalar));
    const follow_detail::EmissionDistance best_scalar =
        follow_detail::emission_distances(model, phi.data(), caps, scalar.data());
    ASSERT_TRUE(set_simd_level(SimdLevel::kAvx2));
    const follow_detail::EmissionDistance best_fast =
        follow_detail::emission_distances(model, phi.data(), caps, fast.data());
    int rounded_otherwise = 0;  // proof that the other kernel ran: another summation order
    for (std::size_t i = 0; i < size; ++i) {
      ASSERT_NEAR(fast[i], scalar[i], 1e-4f * scalar[i]) << "state " << i;
      rounded_otherwise += fast[i] != scalar[i];
    }
    EXPECT_NEAR(best_fast.bounded, best_scalar.bounded, 1e-4f * best_scalar.bounded);
    EXPECT_NEAR(best_fast.plain, best_scalar.plain, 1e-4f * best_scalar.plain);
    if (model.num_dims() > 8) {
      EXPECT_GT(rounded_otherwise, 0);
    }
  }
}

TEST(SimdKernels, Avx2EmissionDistancesMatchTheScalarPath) {
  if (!cpu_has_avx2()) {
    EXPECT_FALSE(set_simd_level(SimdLevel::kAvx2));
    EXPECT_EQ(simd_level(), SimdLevel::kScalar);
    return;
  }
  // Partial last blocks (1003 = 125 x 8 + 3, 5 < 8), whole blocks, D not a multiple of 4.
  const TemplateModel model = test::make_model({600, 403}, 50, 3, 60.0, 8);
  expect_same_distances(model, 4.0f);                                    // capped velocity
  expect_same_distances(model, std::numeric_limits<float>::infinity());  // no cap
  expect_same_distances(test::make_model({1003}, 50, 4), 4.0f);          // no velocity dims
  TemplateModel limbed = test::make_model({600, 403}, 50, 3, 60.0, 8);
  ASSERT_TRUE(limbed.set_limbs(FeatureSpec{}.limb_dims()).ok());
  expect_same_distances(limbed, 4.0f, 1.5f);  // the farthest limb bounded
  expect_same_distances(limbed, 4.0f);        // limbs, no bound
  // Blocked features beyond 4 MB: the kernel's loop that fetches the blocks ahead.
  TemplateModel large = test::make_model({30000, 15003}, 50, 7, 60.0, 8);
  ASSERT_TRUE(large.set_limbs(FeatureSpec{}.limb_dims()).ok());
  ASSERT_GT(large.blocked_features().size_bytes(), std::size_t{4} << 20);
  expect_same_distances(large, 4.0f, 1.5f);
  expect_same_distances(test::make_model({5}, 7, 5, 60.0, 2), 1.0f);
  expect_same_distances(test::make_model({64}, 3, 6, 60.0, 3), 0.5f);  // velocity only
}

TEST(SimdKernels, TheFarthestLimbAndTheVelocitiesCountAtMostTheirBound) {
  // Posture 0..4: dimension 0 in no limb, limbs {1, 2}, {3} and {4}; velocities 5..6.
  FeatureMatrix features(9, 7);  // 9 states: one whole block of 8 and a partial one
  features.setZero();
  features.row(0) << 1, 3, 4, 1, 0, 0, 0;        // limbs 25, 1, 0: 25 counts 3 x 1
  // Values a half float holds exactly (TemplateModel::held_precision).
  features.row(1) << 0, 0.125f, 0.25f, 0, 0, 2, 0;  // limbs 0.078, 0, 0: the floor 0.05;
                                                    // velocity 4 -> 0.3
  features.row(8) << 0, 0, 0, 2, 1, 0, 0;        // limbs 0, 4, 1: 4 counts 3 x 1
  TemplateModel model = TemplateModel::build(features, {}, 60.0, 2).value();
  ASSERT_TRUE(model.set_limbs({{1, 2}, {3}, {4}}).ok());
  const std::vector<float> phi(7, 0.0f);
  const follow_detail::DistanceCaps caps{0.3f, 3.0f, 0.05f};
  const RestoreSimdLevel restore;
  for (const SimdLevel level : {SimdLevel::kScalar, SimdLevel::kAvx2}) {
    if (!set_simd_level(level)) continue;
    std::vector<float> out(9);
    const follow_detail::EmissionDistance best =
        follow_detail::emission_distances(model, phi.data(), caps, out.data());
    EXPECT_FLOAT_EQ(out[0], 1.0f + 3.0f + 1.0f) << to_string(level);
    EXPECT_FLOAT_EQ(out[1], 0.05f + 0.3f) << to_string(level);
    EXPECT_FLOAT_EQ(out[8], 3.0f + 1.0f) << to_string(level);
    EXPECT_FLOAT_EQ(best.bounded, 0.0f);
    EXPECT_FLOAT_EQ(best.plain, 0.0f);
    for (const int i : {0, 1, 8}) {
      const follow_detail::EmissionDistance one =
          follow_detail::state_emission_distance(model, phi.data(), i, caps);
      EXPECT_FLOAT_EQ(one.bounded, out[static_cast<std::size_t>(i)]);
    }
    // The plain distance counts every limb in full (the velocity cap stays).
    EXPECT_FLOAT_EQ(follow_detail::state_emission_distance(model, phi.data(), 0, caps).plain,
                    27.0f);
    EXPECT_FLOAT_EQ(follow_detail::state_emission_distance(model, phi.data(), 1, caps).plain,
                    0.078125f + 0.3f);
    // No bounds: the plain squared distance.
    follow_detail::emission_distances(model, phi.data(), {}, out.data());
    EXPECT_FLOAT_EQ(out[0], 27.0f);
    EXPECT_FLOAT_EQ(out[1], 4.078125f);
    EXPECT_FLOAT_EQ(out[8], 5.0f);
  }
}

TEST(SimdKernels, Avx2ExpIsWithinOneMillionthOfExpOverTheUsedRange) {
  if (!cpu_has_avx2()) {
    EXPECT_EQ(simd_level(), SimdLevel::kScalar);
    return;
  }
  // [-87.33, 0]: where exp is a normal float (the log-emissions minus their maximum).
  std::vector<float> x;
  for (float v = 0.0f; v > -87.33f; v -= 0.0037f) x.push_back(v);
  for (const float v : {-1e-7f, -0.5f * 0.693147f, -88.0f, -100.0f, -1e30f}) x.push_back(v);
  std::vector<float> y(x.size());
  follow_detail::avx2::exp(x.data(), static_cast<int>(x.size()), y.data());
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double exact = std::exp(static_cast<double>(x[i]));
    if (exact < FLT_MIN) {
      EXPECT_LT(y[i], FLT_MIN) << "exp(" << x[i] << ")";
      continue;
    }
    worst = std::max(worst, std::abs(static_cast<double>(y[i]) - exact) / exact);
  }
  std::printf("exp: worst relative error %.3g over %zu points\n", worst, x.size());
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(y[0], 1.0f);
}

TEST(SimdKernels, Avx2ArgmaxIsTheFirstLargestValueLikeTheScalarLoop) {
  if (!cpu_has_avx2()) {
    EXPECT_EQ(simd_level(), SimdLevel::kScalar);
    return;
  }
  std::mt19937 rng(17);
  std::uniform_int_distribution<int> level(0, 5);  // few distinct values: many ties
  for (const int count : {1, 7, 8, 31, 32, 33, 100, 1003, 27495}) {
    std::vector<float> values(static_cast<std::size_t>(count));
    for (int trial = 0; trial < 20; ++trial) {
      for (float& v : values) v = 0.1f * static_cast<float>(level(rng));
      int expected = 0;
      for (int i = 1; i < count; ++i) {
        if (values[static_cast<std::size_t>(i)] > values[static_cast<std::size_t>(expected)]) {
          expected = i;
        }
      }
      ASSERT_EQ(follow_detail::avx2::argmax(values.data(), count), expected) << count;
    }
    // A single largest value in the last element (the scalar tail).
    std::fill(values.begin(), values.end(), 0.0f);
    values.back() = 1.0f;
    EXPECT_EQ(follow_detail::avx2::argmax(values.data(), count), count - 1);
  }
}

// Both followers step through the same frames, one on each path; posteriors within 1e-5.
void expect_same_posteriors(const FollowParams& params) {
  const RestoreSimdLevel restore;
  // Three takes, a dancer who follows take 0 and then jumps into take 2; a 1-state tail block.
  const TemplateModel model = test::make_model({700, 500, 401}, 50, 9, 60.0, 8);
  HmmFollower scalar = HmmFollower::create(model, params).value();
  HmmFollower fast = HmmFollower::create(model, params).value();
  int frames = 0;
  float worst = 0.0f;
  for (int t = 0; t < 400; ++t) {
    const int state = t < 200 ? 100 + t : 1200 + 100 + (t - 200);  // take 2 starts at 1200
    const std::vector<float> phi = query_near(model, state, static_cast<unsigned>(t + 11));
    ASSERT_TRUE(set_simd_level(SimdLevel::kScalar));
    const FollowResult a = scalar.step(phi, 1.0 / 60);
    ASSERT_TRUE(set_simd_level(SimdLevel::kAvx2));
    const FollowResult b = fast.step(phi, 1.0 / 60);
    EXPECT_EQ(a.state, b.state) << "frame " << t;
    EXPECT_NEAR(a.log_likelihood, b.log_likelihood, 1e-3 * (1.0 + std::abs(a.log_likelihood)));
    const std::span<const float> pa = scalar.context().alpha();
    const std::span<const float> pb = fast.context().alpha();
    for (std::size_t i = 0; i < pa.size(); ++i) {
      worst = std::max(worst, std::abs(pa[i] - pb[i]));
      ASSERT_NEAR(pa[i], pb[i], 1e-5f) << "frame " << t << " state " << i;
    }
    ++frames;
  }
  std::printf("sigma %.2f, %d frames: largest posterior difference %.3g\n",
              static_cast<double>(params.emission_sigma), frames, static_cast<double>(worst));
}

TEST(SimdKernels, Avx2ForwardStepsGiveTheScalarPosterior) {
  if (!cpu_has_avx2()) {
    EXPECT_EQ(simd_level(), SimdLevel::kScalar);
    return;
  }
  expect_same_posteriors(FollowParams{});  // peaked: mass on a few states
  FollowParams broad;  // the mass spread over tens of states, so the rounding shows
  broad.emission_sigma = 1.0f;
  broad.pause_distance_per_dim = 0.9f;  // keeps the pause's share as with the defaults
  expect_same_posteriors(broad);
}

}  // namespace
}  // namespace duet
