#include "duet/follow/follower_history.h"

#include <gtest/gtest.h>

#include <limits>

namespace duet {
namespace {

constexpr double k60Hz = 1.0 / 60.0;
constexpr double k30Hz = 1.0 / 30.0;

// Feeds `unexplained` for `frames` frames of `frame_s` each; returns the last decision.
bool feed(FollowerHistory& history, const FollowParams& params, bool unexplained, int frames,
          double frame_s = k60Hz) {
  bool lost = false;
  for (int f = 0; f < frames; ++f) {
    lost = history.confirm_unexplained(params, unexplained, false, frame_s);
  }
  return lost;
}

TEST(FollowerHistory, LostByDistanceOnlyAfterItHoldsForTheConfirmTime) {
  const FollowParams params;  // lost_confirm_s 0.05: three frames at 60 Hz, two at 30 Hz
  ASSERT_FLOAT_EQ(params.lost_confirm_s, 0.05f);
  FollowerHistory history;
  EXPECT_FALSE(feed(history, params, true, 2));  // a two-frame flicker
  EXPECT_FALSE(feed(history, params, false, 1));
  EXPECT_FALSE(feed(history, params, true, 2));
  EXPECT_TRUE(feed(history, params, true, 1));  // the third in a row
  // Followed again only after as long within the distance: a one-frame gap stays lost.
  EXPECT_TRUE(feed(history, params, false, 2));
  EXPECT_TRUE(feed(history, params, true, 1));
  EXPECT_TRUE(feed(history, params, false, 2));
  EXPECT_FALSE(feed(history, params, false, 1));

  FollowerHistory slow;
  EXPECT_FALSE(feed(slow, params, true, 1, k30Hz));
  EXPECT_TRUE(feed(slow, params, true, 1, k30Hz));
}

TEST(FollowerHistory, AfterALongSpellLostTheInputMustHoldLongerToBeFollowed) {
  const FollowParams params;  // 0.25 s per second lost, at most 0.75 s
  ASSERT_FLOAT_EQ(params.found_confirm_per_lost_s, 0.25f);
  ASSERT_FLOAT_EQ(params.found_confirm_max_s, 0.75f);
  EXPECT_DOUBLE_EQ(params.found_confirm_s(0.0), params.lost_confirm_s);
  EXPECT_DOUBLE_EQ(params.found_confirm_s(1.0), 0.25);
  EXPECT_DOUBLE_EQ(params.found_confirm_s(10.0), 0.75);

  // One second lost (3 frames to turn lost, 60 more): followed again after 0.25 s = 15 frames
  // within the distance, not after 14.
  FollowerHistory history;
  EXPECT_TRUE(feed(history, params, true, 63));
  EXPECT_TRUE(feed(history, params, false, 14));
  // A run broken starts over, and the frame past the distance adds to the spell: 61 frames ask
  // for 0.254 s, 16 frames.
  EXPECT_TRUE(feed(history, params, true, 1));
  EXPECT_TRUE(feed(history, params, false, 15));
  EXPECT_FALSE(feed(history, params, false, 1));
  // Followed again, the next spell starts from nothing: a short one asks lost_confirm_s only.
  EXPECT_TRUE(feed(history, params, true, 3));
  EXPECT_TRUE(feed(history, params, false, 2));
  EXPECT_FALSE(feed(history, params, false, 1));

  // Half a minute lost asks for found_confirm_max_s: 23 frames at 30 Hz, not 22.
  FollowerHistory slow;
  EXPECT_TRUE(feed(slow, params, true, 900, k30Hz));
  EXPECT_TRUE(feed(slow, params, false, 22, k30Hz));
  EXPECT_FALSE(feed(slow, params, false, 1, k30Hz));

  // 0 per second lost: lost_confirm_s after any spell.
  FollowParams at_once = params;
  at_once.found_confirm_per_lost_s = 0.0f;
  FollowerHistory quick;
  EXPECT_TRUE(feed(quick, at_once, true, 600));
  EXPECT_TRUE(feed(quick, at_once, false, 2));
  EXPECT_FALSE(feed(quick, at_once, false, 1));
}

TEST(FollowerHistory, AMissingFrameChangesNothingAndResetForgets) {
  const FollowParams params;
  FollowerHistory history;
  EXPECT_FALSE(feed(history, params, true, 2));
  EXPECT_FALSE(history.confirm_unexplained(params, false, true, k60Hz));  // no features
  EXPECT_TRUE(feed(history, params, true, 1));  // the run goes on across it
  EXPECT_TRUE(history.confirm_unexplained(params, false, true, k60Hz));
  history.reset();
  EXPECT_FALSE(feed(history, params, true, 2));
}

TEST(FollowerHistory, ZeroConfirmTimeDecidesEveryFrame) {
  FollowParams params;
  params.lost_confirm_s = 0.0f;
  FollowerHistory history;
  EXPECT_TRUE(feed(history, params, true, 1));
  EXPECT_FALSE(feed(history, params, false, 1));
  EXPECT_TRUE(feed(history, params, true, 1));
}

TEST(FollowerHistory, APauseMajorityIsReportedLostOnlyInThePapersReading) {
  // report_lost(params, gate_lost, past_ceiling, unexplained, missing, frame_s).
  FollowParams params;
  FollowerHistory history;
  // Between places (the gate's flag set by the pause state), the best match explained: not lost.
  EXPECT_FALSE(history.report_lost(params, true, false, false, false, k60Hz));
  // Past the fixed ceiling: lost at once, and a frame without features keeps that.
  EXPECT_TRUE(history.report_lost(params, true, true, true, false, k60Hz));
  EXPECT_TRUE(history.report_lost(params, true, false, false, true, k60Hz));
  EXPECT_FALSE(history.report_lost(params, false, false, false, false, k60Hz));
  // Past the noise-scaled distance: after the confirm time, as confirm_unexplained decides.
  EXPECT_FALSE(history.report_lost(params, false, false, true, false, k60Hz));
  EXPECT_FALSE(history.report_lost(params, false, false, true, false, k60Hz));
  EXPECT_TRUE(history.report_lost(params, false, false, true, false, k60Hz));

  params.pause_reported_lost = true;
  FollowerHistory paper;
  EXPECT_TRUE(paper.report_lost(params, true, false, false, false, k60Hz));
  EXPECT_FALSE(paper.report_lost(params, false, false, false, false, k60Hz));
  EXPECT_TRUE(FollowParams::paper().pause_reported_lost);
}

TEST(FollowerHistory, TheConfirmTimeIsChecked) {
  FollowParams params;
  for (const float bad : {-0.01f, 11.0f, std::numeric_limits<float>::quiet_NaN()}) {
    params.lost_confirm_s = bad;
    EXPECT_FALSE(params.validate(10)) << bad;
  }
  for (const float bad : {-0.01f, 11.0f, std::numeric_limits<float>::quiet_NaN()}) {
    FollowParams found;
    found.found_confirm_per_lost_s = bad;
    EXPECT_FALSE(found.validate(10)) << bad;
    found = FollowParams{};
    found.found_confirm_max_s = bad;
    EXPECT_FALSE(found.validate(10)) << bad;
  }
  EXPECT_TRUE(FollowParams{}.validate(10));
}

TEST(HeldPlace, CountsTheTimeTheEstimateStaysWithinReachOfWhereItBegan) {
  HeldPlace held;
  constexpr int kReach = 12;
  held.update(100, false, k60Hz, kReach);  // the hold begins
  EXPECT_DOUBLE_EQ(held.held_s(), 0.0);
  for (int f = 0; f < 60; ++f) held.update(100 + f % 11 - 5, false, k60Hz, kReach);  // jitter
  EXPECT_NEAR(held.held_s(), 1.0, 1e-9);
  held.update(112, false, k60Hz, kReach);  // a move of the reach: a new hold there
  EXPECT_DOUBLE_EQ(held.held_s(), 0.0);
  held.update(101, false, k60Hz, kReach);  // within reach of 112, not of the old place
  EXPECT_NEAR(held.held_s(), k60Hz, 1e-12);
  held.update(101, true, k60Hz, kReach);  // a jump starts over, even to the same place
  EXPECT_DOUBLE_EQ(held.held_s(), 0.0);
  held.update(101, false, std::numeric_limits<double>::quiet_NaN(), kReach);
  held.update(101, false, -1.0, kReach);
  EXPECT_DOUBLE_EQ(held.held_s(), 0.0);   // no time from a bad interval
  held.update(-1, false, k60Hz, kReach);  // no estimate
  held.update(101, false, k60Hz, kReach);
  EXPECT_DOUBLE_EQ(held.held_s(), 0.0);
  held.update(101, false, k30Hz, kReach);
  held.reset();
  EXPECT_DOUBLE_EQ(held.held_s(), 0.0);
}

TEST(FollowerHistory, TheHeldPlaceLimitsAreChecked) {
  for (const float bad :
       {-1.0f, std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()}) {
    FollowParams params;
    params.held_place_lost_s = bad;
    EXPECT_FALSE(params.validate(10)) << bad;
    params = FollowParams{};
    params.held_place_reach_s = bad;
    EXPECT_FALSE(params.validate(10)) << bad;
    params = FollowParams{};
    params.found_still_spell_s = bad;
    EXPECT_FALSE(params.validate(10)) << bad;
    params = FollowParams{};
    params.found_still_reach_s = bad;
    EXPECT_FALSE(params.validate(10)) << bad;
  }
  FollowParams zero_reach;
  zero_reach.held_place_reach_s = 0.0f;
  EXPECT_FALSE(zero_reach.validate(10));
  zero_reach = FollowParams{};
  zero_reach.found_still_reach_s = 0.0f;
  EXPECT_FALSE(zero_reach.validate(10));
  FollowParams never;
  never.held_place_lost_s = 0.0f;
  never.found_still_spell_s = 0.0f;
  EXPECT_TRUE(never.validate(10));
}

TEST(StillSinceFound, HoldsFromWhereThePlaceWasFoundAgainUntilTheEstimateMovesOn) {
  StillSinceFound still;
  constexpr int kReach = 6;
  constexpr int kNone = -1;
  still.update(300, false, kNone, kReach);  // nothing found again yet
  EXPECT_FALSE(still.still());
  still.update(294, true, 294, kReach);  // found again at 294, by a jump there
  EXPECT_TRUE(still.still());
  for (int f = 0; f < 60; ++f) {  // jitter within reach either way
    still.update(294 + f % 11 - 5, false, kNone, kReach);
    EXPECT_TRUE(still.still()) << f;
  }
  still.update(300, false, kNone, kReach);  // moved on by the reach
  EXPECT_FALSE(still.still());
  still.update(294, false, kNone, kReach);  // back near the place: moved on is moved on
  EXPECT_FALSE(still.still());
  still.update(294, false, 294, kReach);
  still.update(288, false, kNone, kReach);  // the reach back counts too
  EXPECT_FALSE(still.still());
  still.update(340, false, 294, kReach);  // moved on while the follower waited to find it
  EXPECT_FALSE(still.still());
  still.update(297, false, 294, kReach);  // within reach of where the wait began
  EXPECT_TRUE(still.still());
  still.update(295, true, kNone, kReach);  // a jump, even nearby
  EXPECT_FALSE(still.still());
  still.update(294, false, 294, kReach);
  still.update(-1, false, kNone, kReach);  // no estimate
  EXPECT_FALSE(still.still());
  still.update(294, false, 294, kReach);
  still.reset();
  EXPECT_FALSE(still.still());
}

}  // namespace
}  // namespace duet
