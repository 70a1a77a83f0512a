// The jump candidate index's two searches against each other and against the emission distance:
// the k nearest in the projection, and every state within a radius (with its overflow).
#include "duet/follow/jump_candidates.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "follow/synthetic.h"

namespace duet {
namespace {

constexpr int kDims = 40;

float full_distance_sq(const TemplateModel& model, const std::vector<float>& phi, int state) {
  float d2 = 0.0f;
  for (int d = 0; d < model.num_dims(); ++d) {
    const float diff = model.features()(state, d) - phi[static_cast<std::size_t>(d)];
    d2 += diff * diff;
  }
  return d2;
}

class JumpCandidatesTest : public ::testing::Test {
 protected:
  TemplateModel model_ = test::make_model({300, 200}, kDims, 5);
  JumpCandidateIndex index_ = JumpCandidateIndex::build(model_).value();
  std::vector<float> query_ = [this] {
    std::mt19937 rng(9);
    std::vector<float> phi = test::features_at(model_, 123.0);
    test::add_noise(phi, 0.3f, rng);
    return phi;
  }();
};

TEST_F(JumpCandidatesTest, WithinARadiusAreTheNearestStatesCloserThanIt) {
  const int num_states = model_.num_states();
  std::vector<std::uint32_t> all(static_cast<std::size_t>(num_states));
  std::vector<float> all_d2(all.size());
  float bound = 0.0f;
  ASSERT_EQ(index_.nearest(query_.data(), num_states, all.data(), all_d2.data(), bound),
            num_states);
  // A radius between the 40th and the 41st nearest: those 40 exactly.
  const float radius = 0.5f * (all_d2[39] + all_d2[40]);
  ASSERT_LT(all_d2[39], all_d2[40]);
  std::vector<std::uint32_t> within(64);
  std::vector<float> within_d2(64);
  const int found = index_.within(query_.data(), radius, 64, within.data(), within_d2.data());
  ASSERT_EQ(found, 40);
  std::vector<std::uint32_t> expected(all.begin(), all.begin() + 40);
  std::sort(expected.begin(), expected.end());
  within.resize(40);
  std::sort(within.begin(), within.end());
  EXPECT_EQ(within, expected);
  // Every state left out is at least the radius away in the emission distance.
  for (int i = 40; i < num_states; ++i) {
    EXPECT_GE(full_distance_sq(model_, query_, static_cast<int>(all[static_cast<std::size_t>(i)])),
              radius);
  }
}

TEST_F(JumpCandidatesTest, MoreStatesWithinThanRoomIsAnOverflowNotATruncatedAnswer) {
  std::vector<std::uint32_t> states(16);
  std::vector<float> d2(16);
  EXPECT_EQ(index_.within(query_.data(), 1e30f, 16, states.data(), d2.data()), -1);
  EXPECT_EQ(index_.within(query_.data(), 0.0f, 16, states.data(), d2.data()), 0);
}

}  // namespace
}  // namespace duet
