#include "duet/live/duet_library.h"

#include <gtest/gtest.h>

#include "duet/follow/hmm_follower.h"
#include "duet/live/follow_session.h"

namespace duet {
namespace {

std::string salsa(const std::string& subject, const std::string& trial) {
  return std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/" + subject + "/" + subject + "_" + trial +
         "_scaled.bvh";
}

LibraryOptions salsa_options(DancerRole role) {
  LibraryOptions options;
  options.role = role;
  options.load.frame_rate = 60.0;
  return options;
}

TEST(DuetLibrary, ConcatenatesTakesAndSwapsRoles) {
  const std::vector<PairFiles> pairs = {{{salsa("60", "10")}, {salsa("61", "10")}},
                                        {{salsa("60", "05")}, {salsa("61", "05")}}};
  Result<DuetLibrary> leader = DuetLibrary::load(pairs, salsa_options(DancerRole::kLeader));
  ASSERT_TRUE(leader) << leader.error().message;
  EXPECT_EQ(leader.value().model().num_states(), 1197 + 1678);
  EXPECT_EQ(leader.value().model().num_takes(), 2);
  EXPECT_EQ(leader.value().takes()[1].first_state, 1197);
  EXPECT_EQ(leader.value().takes()[0].name, "60_10_scaled");
  EXPECT_DOUBLE_EQ(leader.value().frame_rate(), 60.0);
  // Standardised: every dimension of the template features has mean ~0.
  const auto& features = leader.value().model().features();
  EXPECT_LT(features.colwise().mean().cwiseAbs().maxCoeff(), 1e-3f);
  EXPECT_TRUE(features.allFinite());

  Result<DuetLibrary> partner = DuetLibrary::load(pairs, salsa_options(DancerRole::kPartner));
  ASSERT_TRUE(partner) << partner.error().message;
  // The partner's template is the leader's response and vice versa.
  const Clip& a = leader.value().takes()[0].template_motion.clip;
  const Clip& b = partner.value().takes()[0].response_motion.clip;
  EXPECT_TRUE(a.translations_ls(100)[0].isApprox(b.translations_ls(100)[0]));
}

TEST(DuetLibrary, ThreePointLibrariesHoldOnlyFromAPlaceFollowedAWhile) {
  const FollowParams defaults;
  ASSERT_GT(defaults.unexplained_jump_hold_s, 0.0f);
  const FollowParams body = follow_params_for(InputPoints::kFullBody, defaults);
  EXPECT_EQ(body.unexplained_jump_hold_s, defaults.unexplained_jump_hold_s);
  EXPECT_EQ(body.unexplained_jump_hold_after_s, defaults.unexplained_jump_hold_after_s);
  const FollowParams points = follow_params_for(InputPoints::kHeadHands, defaults);
  EXPECT_EQ(points.unexplained_jump_hold_s, kHeadHandsUnexplainedJumpHoldS);
  EXPECT_EQ(points.unexplained_jump_hold_after_s, defaults.unexplained_jump_hold_after_s);
  EXPECT_GT(points.unexplained_jump_hold_after_s, 0.0f);
  EXPECT_EQ(points.noisy_jump_hold_s, defaults.noisy_jump_hold_s);  // nothing else changes
  EXPECT_TRUE(points.validate(100));
}

TEST(DuetLibrary, ThreePointLibrariesCallAPlaceHeldForTwoSecondsLost) {
  const FollowParams defaults;
  ASSERT_GT(defaults.held_place_lost_s, kHeadHandsHeldPlaceLostS);
  EXPECT_EQ(follow_params_for(InputPoints::kFullBody, defaults).held_place_lost_s,
            defaults.held_place_lost_s);
  EXPECT_EQ(follow_params_for(InputPoints::kHeadHands, defaults).held_place_lost_s,
            kHeadHandsHeldPlaceLostS);
  FollowParams given = defaults;
  given.held_place_lost_s = 0.0f;  // never (the paper preset) stays never
  EXPECT_EQ(follow_params_for(InputPoints::kHeadHands, given).held_place_lost_s, 0.0f);
  given.held_place_lost_s = 1.0f;  // a shorter one stays
  EXPECT_EQ(follow_params_for(InputPoints::kHeadHands, given).held_place_lost_s, 1.0f);
}

TEST(DuetLibrary, ThreePointLibrariesAverageTheRigOffsetOverTheirOwnTime) {
  PostureBiasParams defaults;
  defaults.head_hands_time_constant_s = 2.5;
  defaults.noisy_time_constant_s = 1.5;
  const PostureBiasParams body = posture_bias_params_for(InputPoints::kFullBody, defaults);
  EXPECT_EQ(body.time_constant_s, defaults.time_constant_s);
  EXPECT_EQ(body.noisy_time_constant_s, 1.5);
  const PostureBiasParams points = posture_bias_params_for(InputPoints::kHeadHands, defaults);
  EXPECT_EQ(points.time_constant_s, 2.5);
  EXPECT_EQ(points.noisy_time_constant_s, 2.5);       // never shorter than the steady one
  EXPECT_EQ(points.max_offset, defaults.max_offset);  // nothing else changes
}

TEST(DuetLibrary, RejectsPairsThatAreNotDuets) {
  const std::vector<PairFiles> pairs = {{{salsa("60", "10")}, {salsa("61", "05")}}};
  Result<DuetLibrary> library = DuetLibrary::load(pairs, salsa_options(DancerRole::kLeader));
  ASSERT_FALSE(library);
  EXPECT_NE(library.error().message.find("different frame counts (1197 and 1678)"),
            std::string::npos)
      << library.error().message;
  LibraryOptions trim = salsa_options(DancerRole::kLeader);
  trim.trim_to_shorter = true;
  Result<DuetLibrary> trimmed = DuetLibrary::load(pairs, trim);
  ASSERT_TRUE(trimmed) << trimmed.error().message;
  EXPECT_EQ(trimmed.value().model().num_states(), 1197);
  EXPECT_FALSE(DuetLibrary::load({}, trim));
  Result<DuetLibrary> missing =
      DuetLibrary::load({{{"/nonexistent/a.bvh"}, {salsa("61", "05")}}}, trim);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("/nonexistent/a.bvh"), std::string::npos);
}

TEST(FollowSession, TracksAnUnperturbedTakeExactly) {
  const std::vector<PairFiles> pairs = {{{salsa("60", "10")}, {salsa("61", "10")}},
                                        {{salsa("60", "03")}, {salsa("61", "03")}}};
  Result<DuetLibrary> library = DuetLibrary::load(pairs, salsa_options(DancerRole::kLeader));
  ASSERT_TRUE(library) << library.error().message;
  const DuetTake& take = library.value().takes()[1];
  Result<HmmFollower> follower = HmmFollower::create(library.value().model(), FollowParams{});
  ASSERT_TRUE(follower) << follower.error().message;
  Result<FollowSession> session = FollowSession::create(
      library.value(), take.template_motion.clip.skeleton_ptr(), take.template_motion.roles,
      std::make_unique<HmmFollower>(std::move(follower).value()));
  ASSERT_TRUE(session) << session.error().message;
  const Clip& clip = take.template_motion.clip;
  int exact = 0;
  for (int f = 0; f < clip.frame_count(); ++f) {
    const FollowResult r =
        session.value().step(clip.translations_ls(f), clip.rotations_ls(f), f / 60.0);
    if (r.take == 1 && r.frame_in_take == f) ++exact;
  }
  // After a short lock-in the follower is on the exact frame.
  EXPECT_GE(exact, clip.frame_count() - 30) << exact << " of " << clip.frame_count();
}

}  // namespace
}  // namespace duet
