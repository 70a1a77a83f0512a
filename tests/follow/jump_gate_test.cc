// JumpGate (issue 11): which moves of the posterior's maximum are reported as jumps.
#include "duet/follow/jump_gate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "follow/synthetic.h"

namespace duet {
namespace {

// A follower whose first placement has settled from the first frame (JumpGate::settled): no
// settling time, no forward move asked for.
void settle_at_once(FollowParams& params) {
  params.jump_settle_s = 0.0f;
  params.jump_settle_advance_s = 0.0f;
}

// A posterior with all its mass on `peak` and a little on `also`.
std::vector<float> posterior(int peak, int also = -1) {
  std::vector<float> p(201, 0.0f);
  p[static_cast<std::size_t>(peak)] = 0.9f;
  if (also >= 0) p[static_cast<std::size_t>(also)] = 0.1f;
  return p;
}

FollowResult maximum_at(const TemplateModel& model, const std::vector<float>& p, int state) {
  FollowResult r;
  r.steps = 1;
  r.state = state;
  r.take = model.take_of(state);
  r.frame_in_take = state - model.take_begin(r.take);
  r.jumped = true;       // what decide() says of any move out of the band
  r.window_mass = 1.0f;  // a sure maximum (settles the first placement)
  (void)p;
  return r;
}

// The same from a sensor noisy enough for the whole noisy hold.
FollowResult noisy_maximum_at(const TemplateModel& model, const FollowParams& params, int state) {
  FollowResult r = maximum_at(model, {}, state);
  r.sensor_noise_per_dim = 2.0f * params.noisy_jump_hold_level;
  return r;
}

// A follower whose first placement settles after 6 sure template frames (0.1 s) over which the
// estimate moved 6 frames forward.
FollowParams settling_over_six_frames() {
  FollowParams params;
  params.jump_settle_s = 0.1f;
  params.jump_settle_advance_s = 0.1f;
  return params;
}

// One frame whose sure maximum is `state`, `previous` reported before it; `previous` becomes the
// state reported.
FollowResult step_to(JumpGate& gate, const TemplateModel& model, const FollowParams& params,
                     int& previous, int state) {
  const std::vector<float> p = posterior(state);
  FollowResult r = maximum_at(model, p, state);
  gate.apply(model, params, p.data(), 1.0f, previous, false, r);
  previous = r.state;
  return r;
}

TEST(JumpGate, SmallStepsBackAreJitterLargerOnesAndOtherTakesAreJumps) {
  const TemplateModel model = test::two_ramp_takes();
  FollowParams params;
  params.jump_hold_s = 0.0f;
  params.jump_tolerance_frames = 6;
  params.jump_catch_up_s = 0.0f;  // 50 -> 59 is a catch-up otherwise (tested below)
  settle_at_once(params);  // a follower that has settled (tested below)
  JumpGate gate;
  for (const auto& [from, to, jump] : {std::tuple{50, 47, false},
                                       {50, 44, false},
                                       {50, 43, true},
                                       {50, 52, false},
                                       {50, 58, false},
                                       {50, 59, true},
                                       {50, 150, true}}) {
    gate.reset();
    const std::vector<float> p = posterior(to);
    FollowResult r = maximum_at(model, p, to);
    gate.apply(model, params, p.data(), 1.0f, from, false, r);
    EXPECT_EQ(r.jumped, jump) << from << " -> " << to;
    EXPECT_EQ(r.state, to);
  }
}

TEST(JumpGate, AFarPlaceIsReportedOnlyOnceItHolds) {
  const TemplateModel model = test::two_ramp_takes();
  FollowParams params;
  params.jump_hold_s = 0.05f;  // 3 template frames
  settle_at_once(params);
  JumpGate gate;
  // One frame's excursion to take 1 and back: never reported; the old place goes on.
  std::vector<float> p = posterior(150, 41);
  FollowResult r = maximum_at(model, p, 150);
  gate.apply(model, params, p.data(), 1.0f, 40, false, r);
  EXPECT_FALSE(r.jumped);
  EXPECT_EQ(r.state, 41);
  EXPECT_EQ(r.take, 0);
  EXPECT_EQ(r.frame_in_take, 41);
  EXPECT_NEAR(r.confidence, 0.1f, 1e-6);
  p = posterior(42);
  r = maximum_at(model, p, 42);
  r.jumped = false;
  gate.apply(model, params, p.data(), 1.0f, 41, false, r);
  EXPECT_FALSE(r.jumped);
  EXPECT_EQ(r.state, 42);
  // A real move to take 1 (advancing there, the old place left with 1 % of the mass) is reported
  // on its third frame.
  int previous = 42;
  for (int k = 0; k < 3; ++k) {
    p = posterior(150 + k);
    p[static_cast<std::size_t>(previous + 1)] = 0.01f;
    r = maximum_at(model, p, 150 + k);
    gate.apply(model, params, p.data(), 1.0f, previous, false, r);
    EXPECT_EQ(r.jumped, k == 2) << k;
    EXPECT_EQ(r.state, k == 2 ? 152 : previous + 1) << k;
    previous = r.state;
  }
}

TEST(JumpGate, AfterALostFrameEveryMovePastTheBandIsAJump) {
  const TemplateModel model = test::two_ramp_takes();
  FollowParams params;
  params.jump_tolerance_frames = 6;
  settle_at_once(params);
  JumpGate gate;
  const std::vector<float> p = posterior(53);
  FollowResult r = maximum_at(model, p, 53);
  gate.apply(model, params, p.data(), 1.0f, 50, /*previous_lost=*/true, r);
  EXPECT_TRUE(r.jumped);
  r = maximum_at(model, p, 53);
  gate.apply(model, params, p.data(), 1.0f, 50, /*previous_lost=*/false, r);
  EXPECT_FALSE(r.jumped);
}

TEST(JumpGate, AfterALostFrameTheNewPlaceIsTakenAtOnce) {
  const TemplateModel model = test::two_ramp_takes();
  FollowParams params;
  params.jump_hold_s = 0.5f;
  settle_at_once(params);
  JumpGate gate;
  const std::vector<float> p = posterior(150, 41);
  FollowResult r = maximum_at(model, p, 150);
  gate.apply(model, params, p.data(), 1.0f, 40, /*previous_lost=*/true, r);
  EXPECT_TRUE(r.jumped);
  EXPECT_EQ(r.state, 150);
}

TEST(JumpGate, WhileLostTheWanderingMaximumIsNoJumpAndBeingFoundAgainElsewhereIsOne) {
  const TemplateModel model = test::two_ramp_takes();
  FollowParams params;
  settle_at_once(params);
  params.jump_hold_s = 0.0f;
  const auto adrift_at = [&](int state, bool in_pause) {
    FollowResult r = maximum_at(model, {}, state);
    r.lost = !in_pause;
    r.in_pause = in_pause;
    return r;
  };
  for (const bool found_far : {true, false}) {
    JumpGate gate;
    // Followed at 40, then five frames lost, in the pause state or past the noise-scaled lost
    // distance while the maximum hops between takes: none of them is a jump.
    const std::vector<float> at40 = posterior(40);
    FollowResult steady = maximum_at(model, at40, 40);
    steady.jumped = false;
    gate.apply(model, params, at40.data(), 1.0f, 39, false, steady);
    ASSERT_FALSE(steady.jumped);
    int previous = 40;
    bool previous_lost = false;
    for (const int state : {150, 20, 170, 60, 120}) {
      const std::vector<float> p = posterior(state);
      const bool unexplained = state == 170;
      FollowResult r = adrift_at(state, state % 20 == 0);
      if (unexplained) r.lost = false;
      gate.apply(model, params, p.data(), 1.0f, previous, previous_lost, r, unexplained);
      EXPECT_FALSE(r.jumped) << state;
      EXPECT_EQ(r.state, state);  // the estimate is still the maximum
      previous = state;
      previous_lost = true;
    }
    // Found again: at 48, within reach of 40 after 6 frames (up to 52), no jump; at 160, one.
    const int found = found_far ? 160 : 48;
    const std::vector<float> p = posterior(found);
    FollowResult r = maximum_at(model, p, found);
    gate.apply(model, params, p.data(), 1.0f, previous, previous_lost, r);
    EXPECT_EQ(r.jumped, found_far);
    // The spell is over: the next frame is judged from the place found again.
    const std::vector<float> next = posterior(found + 1);
    r = maximum_at(model, next, found + 1);
    r.jumped = false;
    gate.apply(model, params, next.data(), 1.0f, found, false, r);
    EXPECT_FALSE(r.jumped);
  }
}

TEST(JumpGate, AdriftFromTheFirstFrameIsASpellWithNoPlaceToJumpFrom) {
  // A performance that begins unexplained (three points' `improv-library`: 17 false jumps in its
  // first 2.6 s): the maximum hops between takes before any frame was steady. None of it is a
  // jump, nor is the first place found; from there on, jumps count as usual.
  const TemplateModel model = test::two_ramp_takes();
  FollowParams params;
  settle_at_once(params);  // settled at once, as after a performance's first 0.3 s
  params.jump_hold_s = 0.0f;
  JumpGate gate;
  int previous = -1;
  for (const int state : {150, 20, 170, 60, 120, 30}) {
    const std::vector<float> p = posterior(state);
    FollowResult r = maximum_at(model, p, state);
    r.lost = true;
    gate.apply(model, params, p.data(), 1.0f, previous, previous >= 0, r, true);
    EXPECT_FALSE(r.jumped) << state;
    EXPECT_EQ(r.state, state);
    previous = state;
  }
  const std::vector<float> found = posterior(160);
  FollowResult r = maximum_at(model, found, 160);
  gate.apply(model, params, found.data(), 1.0f, previous, true, r);
  EXPECT_FALSE(r.jumped);
  const std::vector<float> next = posterior(161);
  r = maximum_at(model, next, 161);
  gate.apply(model, params, next.data(), 1.0f, 160, false, r);
  EXPECT_FALSE(r.jumped);
  const std::vector<float> far = posterior(40);
  r = maximum_at(model, far, 40);
  gate.apply(model, params, far.data(), 1.0f, 161, false, r);
  EXPECT_TRUE(r.jumped);
}

TEST(JumpGate, AMoveBetweenPlacesThatLookAlikeIsNoJump) {
  // Both takes begin with ten frames of standing still, the same to within 0.001 per dimension.
  FeatureMatrix f = FeatureMatrix::Zero(200, 2);
  for (int i = 0; i < 200; ++i) {
    f(i, 0) = i % 100 < 10 ? 0.03f * static_cast<float>(i / 100) : static_cast<float>(i);
  }
  const TemplateModel model =
      std::move(TemplateModel::build(std::move(f), {0, 100}, 60.0, 0)).value();
  FollowParams params;
  settle_at_once(params);
  for (const auto& [to, jump] : {std::pair{105, false}, {150, true}}) {
    JumpGate gate;
    const std::vector<float> p = posterior(to);
    FollowResult r = maximum_at(model, p, to);
    gate.apply(model, params, p.data(), 1.0f, 5, false, r);
    EXPECT_EQ(r.jumped, jump) << to;
    EXPECT_EQ(r.state, to);  // the estimate moves there either way
  }
  params.jump_alike_distance_per_dim = 0.0f;  // off: every far move is a jump
  JumpGate gate;
  const std::vector<float> p = posterior(105);
  FollowResult r = maximum_at(model, p, 105);
  gate.apply(model, params, p.data(), 1.0f, 5, false, r);
  EXPECT_TRUE(r.jumped);
}

TEST(JumpGate, TheFirstPlacementIsRefinedWithoutJumpsUntilItHasSettled) {
  const TemplateModel model = test::two_ramp_takes();
  FollowParams params;
  params.jump_settle_s = 0.1f;  // 6 template frames
  params.jump_settle_advance_s = 0.1f;  // the same 6 frames move forward
  JumpGate gate;
  // The first frames move between look-alike places: no jump is reported, the place is taken.
  int previous = -1;
  for (const int to : {10, 150, 151, 60}) {
    const std::vector<float> p = posterior(to);
    FollowResult r = maximum_at(model, p, to);
    gate.apply(model, params, p.data(), 1.0f, previous, false, r);
    EXPECT_FALSE(r.jumped) << to;
    EXPECT_EQ(r.state, to);
    previous = r.state;
  }
  // Six frames along one place settle it (0.1 s); a far move is then a jump again.
  for (int k = 1; k <= 6; ++k) {
    const std::vector<float> p = posterior(60 + k);
    FollowResult r = maximum_at(model, p, 60 + k);
    gate.apply(model, params, p.data(), 1.0f, previous, false, r);
    EXPECT_FALSE(r.jumped);
    previous = r.state;
  }
  std::vector<float> p = posterior(140);
  FollowResult r = maximum_at(model, p, 140);
  gate.apply(model, params, p.data(), 1.0f, previous, false, r);
  EXPECT_TRUE(r.jumped);
  // Frames the follower is unsure of (window mass under jump_settle_mass) do not settle it.
  JumpGate unsure;
  previous = 60;
  for (int k = 1; k <= 12; ++k) {
    const std::vector<float> q = posterior(60 + k);
    FollowResult u = maximum_at(model, q, 60 + k);
    u.window_mass = 0.9f;
    unsure.apply(model, params, q.data(), 1.0f, previous, false, u);
    previous = u.state;
  }
  FollowResult far = maximum_at(model, p, 140);
  far.window_mass = 0.9f;
  unsure.apply(model, params, p.data(), 1.0f, previous, false, far);
  EXPECT_FALSE(far.jumped);
  EXPECT_EQ(far.state, 140);
  // reset() starts the first placement over.
  gate.reset();
  p = posterior(20);
  r = maximum_at(model, p, 20);
  gate.apply(model, params, p.data(), 1.0f, 140, false, r);
  EXPECT_FALSE(r.jumped);
}

TEST(JumpGate, TheFirstPlacementSettlesOnlyOnceTheEstimateMovesForward) {
  const TemplateModel model = test::two_ramp_takes();
  const FollowParams params = settling_over_six_frames();
  JumpGate gate;
  // Half a second sure of one standing frame (as a standing start is): time alone does not
  // settle the placement, so a move to another take's look-alike is no jump.
  int previous = 60;
  for (int k = 0; k < 30; ++k) EXPECT_FALSE(step_to(gate, model, params, previous, 60).jumped);
  EXPECT_FALSE(gate.settled(params));
  FollowResult r = step_to(gate, model, params, previous, 140);
  EXPECT_FALSE(r.jumped);
  EXPECT_EQ(r.state, 140);
  // Five frames forward are not yet 0.1 s of the take; the sixth settles it.
  for (int k = 1; k <= 6; ++k) {
    EXPECT_FALSE(gate.settled(params)) << k;
    EXPECT_FALSE(step_to(gate, model, params, previous, 140 + k).jumped);
  }
  EXPECT_TRUE(gate.settled(params));
  EXPECT_TRUE(step_to(gate, model, params, previous, 20).jumped);
}

TEST(JumpGate, JitterBackAndForthIsNoMoveForward) {
  const TemplateModel model = test::two_ramp_takes();
  const FollowParams params = settling_over_six_frames();
  JumpGate gate;
  // A standing start read through a noisy suit: the maximum jitters 3 frames forward and back
  // about one place for a second. Summed, its forward steps would make 0.5 s; it has gone 3
  // frames forward of where it began.
  int previous = 60;
  for (int k = 0; k < 60; ++k) {
    EXPECT_FALSE(step_to(gate, model, params, previous, 60 + (k / 3) % 2 * 3).jumped);
  }
  EXPECT_FALSE(gate.settled(params));
  // Three frames past the furthest it had reached make the six from where it began.
  for (int state = 64; state <= 66; ++state) {
    EXPECT_FALSE(gate.settled(params)) << state;
    step_to(gate, model, params, previous, state);
  }
  EXPECT_TRUE(gate.settled(params));
}

TEST(JumpGate, UnderANoisySensorAOneFrameExcursionIsNoJump) {
  FollowParams params;
  // The hold grows with the estimated sensor noise: none on a clean sensor, all of it from the
  // level on, the larger of it and jump_hold_s.
  EXPECT_EQ(JumpGate::hold_s(params, 0.0f), 0.0f);
  EXPECT_EQ(JumpGate::hold_s(params, 0.5f * params.noisy_jump_hold_level), 0.0f);
  EXPECT_NEAR(JumpGate::hold_s(params, 0.75f * params.noisy_jump_hold_level),
              0.5f * params.noisy_jump_hold_s, 1e-6f);
  EXPECT_EQ(JumpGate::hold_s(params, 10.0f * params.noisy_jump_hold_level),
            params.noisy_jump_hold_s);
  EXPECT_EQ(JumpGate::hold_s(params, std::nanf("")), 0.0f);
  params.jump_hold_s = 0.5f;
  EXPECT_EQ(JumpGate::hold_s(params, 1.0f), 0.5f);
  params.jump_hold_s = 0.0f;
  settle_at_once(params);

  const TemplateModel model = test::two_ramp_takes();
  const auto noisy = [&](int state) { return noisy_maximum_at(model, params, state); };
  // One frame at take 1 and back: the old place goes on, no jump either way.
  JumpGate gate;
  std::vector<float> p = posterior(150, 41);
  FollowResult r = noisy(150);
  gate.apply(model, params, p.data(), 1.0f, 40, false, r);
  EXPECT_FALSE(r.jumped);
  EXPECT_EQ(r.state, 41);
  p = posterior(42);
  r = noisy(42);
  r.jumped = false;
  gate.apply(model, params, p.data(), 1.0f, 41, false, r);
  EXPECT_FALSE(r.jumped);
  // A real jump holds: reported on its third frame at 60 Hz (0.05 s >= 0.04 s); the old place
  // keeps too little mass to hold it back.
  int previous = 42;
  for (int k = 0; k < 3; ++k) {
    p = posterior(150 + k);
    p[static_cast<std::size_t>(previous + 1)] = 0.01f;
    r = noisy(150 + k);
    gate.apply(model, params, p.data(), 1.0f, previous, false, r);
    EXPECT_EQ(r.jumped, k == 2) << k;
    previous = r.state;
  }
  // On a clean sensor there is no hold: a far place is a jump at once when the old place has
  // lost its mass, but not while it keeps a tenth of it (a look-alike's brief maximum).
  JumpGate clean;
  p = posterior(150, 41);
  r = maximum_at(model, p, 150);
  clean.apply(model, params, p.data(), 1.0f, 40, false, r);
  EXPECT_FALSE(r.jumped);
  EXPECT_EQ(r.state, 41);
  JumpGate clean_jump;
  p = posterior(150);
  r = maximum_at(model, p, 150);
  clean_jump.apply(model, params, p.data(), 1.0f, 40, false, r);
  EXPECT_TRUE(r.jumped);
}

TEST(JumpGate, UnderANoisySensorAFarPlaceWaitsUntilTheOldPlaceHasLostItsMass) {
  FollowParams params;
  settle_at_once(params);
  const TemplateModel model = test::two_ramp_takes();
  const auto noisy = [&](int state) { return noisy_maximum_at(model, params, state); };
  // The maximum sits at take 1 for six frames while the old place (the band's reach of the
  // reported state) keeps 10 % of the mass: no jump, the old place goes on.
  JumpGate gate;
  int previous = 40;
  for (int k = 0; k < 6; ++k) {
    std::vector<float> p = posterior(150 + k, previous + 1);
    FollowResult r = noisy(150 + k);
    gate.apply(model, params, p.data(), 1.0f, previous, false, r);
    EXPECT_FALSE(r.jumped) << k;
    EXPECT_EQ(r.state, previous + 1) << k;
    previous = r.state;
  }
  // Its mass gone (1 % left), the far place that has held on is reported at once.
  std::vector<float> p = posterior(156);
  p[static_cast<std::size_t>(previous + 1)] = 0.01f;
  FollowResult r = noisy(156);
  gate.apply(model, params, p.data(), 1.0f, previous, false, r);
  EXPECT_TRUE(r.jumped);
  EXPECT_EQ(r.state, 156);
  // With the criterion off (1) the hold alone decides: the third frame is a jump.
  params.jump_old_place_mass = 1.0f;
  JumpGate hold_only;
  previous = 40;
  for (int k = 0; k < 3; ++k) {
    p = posterior(150 + k, previous + 1);
    r = noisy(150 + k);
    hold_only.apply(model, params, p.data(), 1.0f, previous, false, r);
    EXPECT_EQ(r.jumped, k == 2) << k;
    previous = r.state;
  }
}

TEST(JumpGate, AFarPlaceTheInputFitsPoorlyWaitsTheLongerHold) {
  FollowParams params;
  const float noise = 0.0015f;  // about 2 degrees per axis: no noisy hold yet
  const float fits = params.unexplained_jump_ratio * noise;
  ASSERT_GT(fits, params.lost_residual_per_dim);
  EXPECT_EQ(JumpGate::hold_s(params, noise, 0.9f * fits), JumpGate::hold_s(params, noise));
  EXPECT_EQ(JumpGate::hold_s(params, noise, 1.1f * fits), params.unexplained_jump_hold_s);
  EXPECT_EQ(JumpGate::hold_s(params, noise, std::nanf("")), JumpGate::hold_s(params, noise));
  // On a clean sensor the lost residual is the floor of what fits.
  EXPECT_EQ(JumpGate::hold_s(params, 0.0f, 0.9f * params.lost_residual_per_dim), 0.0f);
  EXPECT_EQ(JumpGate::hold_s(params, 0.0f, 1.1f * params.lost_residual_per_dim),
            params.unexplained_jump_hold_s);
  params.unexplained_jump_hold_s = 0.0f;
  EXPECT_EQ(JumpGate::hold_s(params, noise, 10.0f * fits), JumpGate::hold_s(params, noise));
  params.unexplained_jump_hold_s = 0.4f;
  params.unexplained_jump_hold_after_s = 0.0f;  // from every place (tested below)
  settle_at_once(params);

  // An arm held where it was last seen fits take 1 better for a moment, and poorly: the old
  // place goes on until the far place has held for 0.4 s (24 frames at 60 Hz).
  const TemplateModel model = test::two_ramp_takes();
  const auto far = [&](int state, float distance) {
    FollowResult r = maximum_at(model, {}, state);
    r.sensor_noise_per_dim = noise;
    r.best_distance_per_dim = distance;
    return r;
  };
  JumpGate gate;
  int previous = 40;
  for (int k = 0; k < 24; ++k) {
    const std::vector<float> p = posterior(120 + k);
    FollowResult r = far(120 + k, 2.0f * fits);
    gate.apply(model, params, p.data(), 1.0f, previous, false, r);
    EXPECT_EQ(r.jumped, k == 23) << k;
    if (k < 23) {
      EXPECT_EQ(model.take_of(r.state), 0) << k;
    }
    previous = r.state;
  }
  // A far place that fits as well as the noise allows is taken at once.
  JumpGate fitting;
  const std::vector<float> p = posterior(150);
  FollowResult r = far(150, 0.5f * fits);
  fitting.apply(model, params, p.data(), 1.0f, 40, false, r);
  EXPECT_TRUE(r.jumped);
}

TEST(JumpGate, APlaceJustLandedOnIsLeftAtOnceOneFollowedForAWhileWaits) {
  FollowParams params;
  settle_at_once(params);
  params.unexplained_jump_hold_s = 0.3f;                     // 18 frames at 60 Hz
  params.unexplained_jump_hold_after_s = 0.5f;               // 30 frames
  params.jump_burst_jumps = 0;  // three jumps in 1.2 s: no burst here (the next test)
  params.jump_catch_up_s = 0.0f;                             // 120 -> 130 is a catch-up otherwise
  const float poorly = 2.0f * params.lost_residual_per_dim;  // clean sensor: over the floor
  EXPECT_EQ(JumpGate::hold_s(params, 0.0f, poorly, 0.49), 0.0f);
  EXPECT_EQ(JumpGate::hold_s(params, 0.0f, poorly, 0.5), 0.3f);
  EXPECT_EQ(JumpGate::hold_s(params, 0.0f, poorly), 0.3f);  // followed time not given

  const TemplateModel model = test::two_ramp_takes();
  const auto poorly_fitted_step = [&](JumpGate& gate, int& previous, int state) {
    const std::vector<float> p = posterior(state);
    FollowResult r = maximum_at(model, p, state);
    r.best_distance_per_dim = poorly;
    gate.apply(model, params, p.data(), 1.0f, previous, false, r);
    previous = r.state;
    return r;
  };
  // A jump to take 1 lands at 110; 10 frames on (0.17 s followed), the maximum moves to 130 (the
  // landing refined): a jump at once.
  JumpGate gate;
  int previous = 20;
  poorly_fitted_step(gate, previous, 21);
  ASSERT_TRUE(poorly_fitted_step(gate, previous, 110).jumped);
  for (int k = 1; k <= 10; ++k) poorly_fitted_step(gate, previous, 110 + k);
  EXPECT_TRUE(poorly_fitted_step(gate, previous, 130).jumped);
  // Followed from there for 40 frames (0.67 s), a far maximum waits the hold: 17 frames of it
  // report the old place, the 18th is the jump.
  for (int k = 1; k <= 40; ++k) poorly_fitted_step(gate, previous, 130 + k);
  ASSERT_EQ(previous, 170);
  for (int k = 0; k < 18; ++k) {
    const FollowResult r = poorly_fitted_step(gate, previous, 10 + k);
    EXPECT_EQ(r.jumped, k == 17) << k;
    if (k < 17) {
      EXPECT_EQ(model.take_of(r.state), 1) << k;
    }
  }
}

TEST(JumpGate, ABurstOfJumpsIsAPlaceLostFoundAgainWithoutJumps) {
  const TemplateModel model = test::two_ramp_takes();
  FollowParams params;
  params.jump_hold_s = 0.0f;
  params.noisy_jump_hold_s = 0.0f;
  params.jump_settle_s = 0.1f;          // 6 sure frames
  params.jump_settle_advance_s = 0.1f;  // over 6 frames forward
  params.jump_burst_jumps = 3;
  params.jump_burst_s = 1.0f;  // 60 template frames
  JumpGate gate;
  int previous = 10;
  for (int k = 1; k <= 10; ++k) step_to(gate, model, params, previous, 10 + k);  // settled
  // Two far moves 20 frames apart are jumps; a third within the second is withdrawn, and the
  // placement starts again.
  EXPECT_TRUE(step_to(gate, model, params, previous, 150).jumped);
  for (int k = 1; k <= 20; ++k) step_to(gate, model, params, previous, 150 + k);
  EXPECT_TRUE(step_to(gate, model, params, previous, 40).jumped);
  for (int k = 1; k <= 20; ++k) step_to(gate, model, params, previous, 40 + k);
  FollowResult third = step_to(gate, model, params, previous, 120);
  EXPECT_FALSE(third.jumped);
  EXPECT_EQ(third.state, 120);  // the estimate moves all the same
  // Until the placement has settled again, far moves are no jumps either.
  EXPECT_FALSE(step_to(gate, model, params, previous, 30).jumped);
  for (int k = 1; k <= 5; ++k) step_to(gate, model, params, previous, 30 + k);
  EXPECT_FALSE(step_to(gate, model, params, previous, 160).jumped);  // not yet settled
  // Six frames forward, sure of them: settled again; the next far move is a jump.
  for (int k = 1; k <= 6; ++k) step_to(gate, model, params, previous, 160 + k);
  EXPECT_TRUE(step_to(gate, model, params, previous, 60).jumped);
  // Jumps further apart than jump_burst_s make no burst.
  for (int round = 0; round < 4; ++round) {
    const int far = previous >= 100 ? 20 : 110;
    EXPECT_TRUE(step_to(gate, model, params, previous, far).jumped) << round;
    for (int k = 1; k <= 61; ++k) step_to(gate, model, params, previous, far + k);
  }
  // Without the limit every far move is a jump.
  params.jump_burst_jumps = 0;
  JumpGate unlimited;
  previous = 10;
  for (int k = 1; k <= 10; ++k) step_to(unlimited, model, params, previous, 10 + k);
  for (const int far : {150, 40, 120, 30}) {
    EXPECT_TRUE(step_to(unlimited, model, params, previous, far).jumped) << far;
  }
}

TEST(JumpGate, ACatchUpWithinTheTakeIsNoJump) {
  const TemplateModel model = test::two_ramp_takes();
  FollowParams params;
  params.jump_hold_s = 0.0f;
  params.noisy_jump_hold_s = 0.0f;
  params.jump_tolerance_frames = 6;
  params.jump_catch_up_s = 0.25f;  // 15 frames past the band's reach (2 frames a step)
  settle_at_once(params);
  const auto move = [&](int from, int to, bool previous_lost = false) {
    JumpGate gate;
    const std::vector<float> p = posterior(to);
    FollowResult r = maximum_at(model, p, to);
    gate.apply(model, params, p.data(), 1.0f, from, previous_lost, r);
    EXPECT_EQ(r.state, to);  // the estimate moves whether or not it is a jump
    return r.jumped;
  };
  EXPECT_FALSE(move(50, 58));  // within the band and its tolerance: as before
  EXPECT_FALSE(move(50, 67));  // 15 frames past the band's reach (50 + 2): a catch-up
  EXPECT_TRUE(move(50, 68));   // one more: a jump
  EXPECT_TRUE(move(50, 40));   // back past the tolerance: a jump
  EXPECT_TRUE(move(90, 105));  // forward into another take: a jump
  EXPECT_TRUE(move(50, 60, /*previous_lost=*/true));  // a landing refined after a lost frame
  // Found again after a spell adrift, the catch-up is counted from the place before the spell
  // over the spell's steps: 10 frames adrift reach 50 + 2 x 11, and 15 frames more.
  for (const auto& [to, jump] : {std::pair{87, false}, std::pair{88, true}}) {
    JumpGate gate;
    int previous = 49;
    step_to(gate, model, params, previous, 50);
    for (int k = 0; k < 10; ++k) {
      const std::vector<float> p = posterior(120);
      FollowResult r = maximum_at(model, p, 120);
      r.in_pause = true;
      gate.apply(model, params, p.data(), 1.0f, previous, false, r);
      EXPECT_FALSE(r.jumped);
      previous = r.state;
    }
    EXPECT_EQ(step_to(gate, model, params, previous, to).jumped, jump) << to;
  }
  params.jump_catch_up_s = 0.0f;
  EXPECT_TRUE(move(50, 60));
}

TEST(FollowParams, ASettlePeriodOrNoisyHoldOutOfRangeIsRejected) {
  EXPECT_TRUE(FollowParams{}.validate(200));
  const float nan = std::nanf("");
  // Each field set out of its range on the defaults, the rest left valid.
  const std::vector<std::pair<const char*, void (*)(FollowParams&, float)>> fields = {
      {"jump_settle_s", [](FollowParams& p, float v) { p.jump_settle_s = v; }},
      {"noisy_jump_hold_s", [](FollowParams& p, float v) { p.noisy_jump_hold_s = v; }},
      {"unexplained_jump_hold_s", [](FollowParams& p, float v) { p.unexplained_jump_hold_s = v; }},
      {"unexplained_jump_hold_after_s",
       [](FollowParams& p, float v) { p.unexplained_jump_hold_after_s = v; }},
      {"jump_settle_advance_s", [](FollowParams& p, float v) { p.jump_settle_advance_s = v; }},
      {"jump_burst_s", [](FollowParams& p, float v) { p.jump_burst_s = v; }},
      {"jump_catch_up_s", [](FollowParams& p, float v) { p.jump_catch_up_s = v; }},
  };
  for (const auto& [name, set] : fields) {
    for (const float bad : {-1.0f, nan, 1000.0f}) {
      FollowParams params;
      set(params, bad);
      EXPECT_FALSE(params.validate(200)) << name << " = " << bad;
    }
    FollowParams params;
    set(params, 0.0f);
    EXPECT_TRUE(params.validate(200)) << name << " = 0";
  }
  // The message names the field, its range and unit, and the value.
  FollowParams after;
  after.unexplained_jump_hold_after_s = 61.0f;
  const Status too_long = after.validate(200);
  ASSERT_FALSE(too_long);
  EXPECT_NE(
      too_long.error().message.find("unexplained_jump_hold_after_s must be in [0, 60] s, got 61"),
      std::string::npos)
      << too_long.error().message;
  FollowParams factor;
  factor.found_confirm_per_lost_s = 11.0f;
  const Status too_large = factor.validate(200);
  ASSERT_FALSE(too_large);
  EXPECT_NE(too_large.error().message.find("found_confirm_per_lost_s must be in [0, 10], got 11"),
            std::string::npos)
      << too_large.error().message;
  const std::vector<std::pair<const char*, void (*)(FollowParams&)>> others = {
      {"noisy_jump_hold_level 0", [](FollowParams& p) { p.noisy_jump_hold_level = 0.0f; }},
      {"unexplained_jump_ratio 0", [](FollowParams& p) { p.unexplained_jump_ratio = 0.0f; }},
      {"unexplained_jump_ratio inf",
       [](FollowParams& p) { p.unexplained_jump_ratio = std::numeric_limits<float>::infinity(); }},
      {"jump_old_place_mass 1.5", [](FollowParams& p) { p.jump_old_place_mass = 1.5f; }},
      {"jump_old_place_mass nan", [](FollowParams& p) { p.jump_old_place_mass = std::nanf(""); }},
      {"jump_settle_mass -0.5", [](FollowParams& p) { p.jump_settle_mass = -0.5f; }},
      {"jump_burst_jumps -1", [](FollowParams& p) { p.jump_burst_jumps = -1; }},
      {"jump_burst_jumps 9", [](FollowParams& p) { p.jump_burst_jumps = 9; }},
  };
  for (const auto& [what, set] : others) {
    FollowParams params;
    set(params);
    EXPECT_FALSE(params.validate(200)) << what;
  }
}

}  // namespace
}  // namespace duet
