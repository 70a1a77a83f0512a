// The emission's bound on one limb out of line (FollowParams::limb_outlier_ratio): a limb held
// where it was last seen does not pull the estimate to a place that fits only that limb.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "duet/follow/follow_params.h"
#include "duet/follow/hmm_follower.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

constexpr int kFrames = 300;
constexpr int kHoldFrom = 100;  // the arm is held from this frame on
constexpr float kShift = 0.1f;  // the other take's other limbs are off by this per dimension

// Dimension 0 is the trunk; the limbs are {1, 2} (the arm that is held), {3, 4} and {5, 6}.
const std::vector<std::vector<int>> kLimbs = {{1, 2}, {3, 4}, {5, 6}};

struct HeldArm {
  TemplateModel model;
  FeatureMatrix input;  // take 0 with the arm held from kHoldFrom on
};

// Take 0 is a dance; take 1 is take 0 with the arm held from kHoldFrom on (as the input has it)
// but its other two limbs off by kShift: it fits the held arm exactly and the rest of the body
// poorly.
HeldArm make_held_arm() {
  const FeatureMatrix dance = test::smooth_walk(kFrames, 7, 5);
  FeatureMatrix input = dance;
  for (int t = kHoldFrom; t < kFrames; ++t) {
    input(t, 1) = dance(kHoldFrom, 1);
    input(t, 2) = dance(kHoldFrom, 2);
  }
  FeatureMatrix other = input;
  other.rightCols(4).array() += kShift;
  FeatureMatrix both(2 * kFrames, 7);
  both << dance, other;
  TemplateModel model = TemplateModel::build(both, {0, kFrames}, 60.0).value();
  EXPECT_TRUE(model.set_limbs(kLimbs).ok());
  return {std::move(model), std::move(input)};
}

FollowParams params_for(float limb_ratio) {
  FollowParams params;
  params.limb_outlier_ratio = limb_ratio;
  // On this small model's scale (the other take is 0.04 off, the pause level 0.063).
  params.limb_outlier_floor = 0.01f;
  // The fixed lost level: the other take's place is not lost, so it can be jumped to.
  params.lost_residual_per_dim = std::numeric_limits<float>::infinity();
  return params;
}

struct Followed {
  int in_own_take = 0;    // late frames estimated within 10 frames of the truth in take 0
  int in_other_take = 0;  // late frames estimated in take 1
  int out_of_line = 0;    // late frames reported with a limb out of line
  int best_is_plain = 0;  // late frames whose best distance is the plain minimum (every limb)
};

// min_i ||input_t - phi_i||^2 over the model's states, every limb in full.
float plain_best(const TemplateModel& model, const FeatureMatrix& input, int t) {
  return (model.features().rowwise() - input.row(t)).rowwise().squaredNorm().minCoeff();
}

Followed follow(const HeldArm& held, float limb_ratio) {
  HmmFollower follower = HmmFollower::create(held.model, params_for(limb_ratio)).value();
  Followed out;
  for (int t = 0; t < kFrames; ++t) {
    const FollowResult r =
        follower.step(std::span<const float>(held.input.row(t).data(), 7), 1.0 / 60.0);
    // Late: the held arm is far from where the dance has taken it.
    if (t < kHoldFrom + 50) continue;
    out.in_own_take += r.state >= 0 && r.state < kFrames && std::abs(r.state - t) <= 10;
    out.in_other_take += r.state >= kFrames;
    out.out_of_line += r.limb_out_of_line;
    const float plain = plain_best(held.model, held.input, t);
    out.best_is_plain += std::abs(r.best_distance_per_dim * 7.0f - plain) <= 1e-4f + 1e-4f * plain;
  }
  return out;
}

TEST(LimbBound, AHeldArmDoesNotPullTheEstimateToAPlaceThatFitsOnlyThatArm) {
  const HeldArm held = make_held_arm();
  const int late = kFrames - kHoldFrom - 50;
  // Unbounded, the other take fits better (0.04 against the held arm's distance).
  const Followed plain = follow(held, std::numeric_limits<float>::infinity());
  EXPECT_GT(plain.in_other_take, late / 2);
  EXPECT_EQ(plain.out_of_line, 0);
  // Bounded, the held arm counts at most the floor: the dance's own place wins.
  const Followed bounded = follow(held, 3.0f);
  EXPECT_GE(bounded.in_own_take, late * 9 / 10);
  EXPECT_EQ(bounded.in_other_take, 0);
  EXPECT_GE(bounded.out_of_line, late * 9 / 10);
  // How far the input is from the library counts every limb, whatever the emission weighs.
  EXPECT_EQ(bounded.best_is_plain, late);
  EXPECT_EQ(plain.best_is_plain, late);
}

}  // namespace
}  // namespace duet
