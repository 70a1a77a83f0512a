// FootHold on hand-made ankle paths: held feet stay put while the pose slides under them, steps
// lift before they cross, holds start only in a blend, and bad input leaves the feet alone.
#include "duet/partner/foot_hold.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "duet/math/rotation.h"

namespace duet {
namespace {

constexpr double kDt = 1.0 / 60.0;
constexpr double kLeg = 0.84;  // thigh + shin
constexpr double kHipHeight = 0.9;

// Two feet 0.2 m apart at ankle height 0.08 under hips that carry them; `shift` moves the whole
// pose (hips and ankles) along +X, as the blend carries the partner to a new place.
struct Pose {
  std::array<Vec3, 2> ankles;
  std::array<Quat, 2> rotations{Quat::Identity(), Quat::Identity()};
  std::array<Vec3, 2> hips;
  std::array<double, 2> legs{kLeg, kLeg};

  explicit Pose(double shift, double yaw = 0.0) {
    for (std::size_t i = 0; i < 2; ++i) {
      const double x = shift + (i == 0 ? 0.1 : -0.1);
      ankles[i] = Vec3(x, 0.08, 0.0);
      hips[i] = Vec3(x, kHipHeight, 0.0);
      rotations[i] = yaw_rotation(yaw);
    }
  }
};

FootHoldParams on() {
  FootHoldParams params;
  params.enabled = true;
  return params;
}

double horizontal(const Vec3& a, const Vec3& b) {
  return std::hypot(a.x() - b.x(), a.z() - b.z());
}

TEST(FootHold, HoldsPlantedFeetWhileTheBlendCarriesThePoseAndStepsToCatchUp) {
  FootHold hold;
  const FootHoldParams params = on();
  const std::array<bool, 2> planted{true, true};
  std::array<Vec3, 2> previous{Vec3::Zero(), Vec3::Zero()};
  double highest = 0.0;
  int steps = 0;
  bool was_stepping = false;
  for (int f = 0; f < 60; ++f) {
    // The pose crosses 0.9 m at 1.8 m/s (3 cm a frame), then stands.
    const Pose pose(std::min(f, 30) * 0.03);
    hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, planted, f < 40, f == 0,
                params, kDt);
    for (int i = 0; i < 2; ++i) {
      const FootHoldTarget& t = hold.target(i);
      ASSERT_TRUE(t.active || f >= 40) << "frame " << f;
      const Vec3 at = t.active ? t.position_ws : pose.ankles[static_cast<std::size_t>(i)];
      const double lifted = at.y() - 0.08;
      highest = std::max(highest, lifted);
      if (f > 0) {
        // A foot on the floor (not raised by a step) does not move horizontally.
        const double moved = horizontal(at, previous[static_cast<std::size_t>(i)]);
        if (lifted < 0.01) {
          EXPECT_LT(moved / kDt, 0.3) << "frame " << f << " foot " << i;
        }
      }
      previous[static_cast<std::size_t>(i)] = at;
    }
    const bool stepping = hold.stepping(0) || hold.stepping(1);
    if (stepping && !was_stepping) ++steps;
    was_stepping = stepping;
  }
  EXPECT_GE(steps, 2);  // 0.9 m takes more than one step
  EXPECT_NEAR(highest, params.step_height_m, 0.01);
  // The feet arrive: where the pose stands now, within a step trigger, and are let go or held
  // in reach.
  const Pose end(0.9);
  for (int i = 0; i < 2; ++i) {
    const FootHoldTarget& t = hold.target(i);
    const Vec3 at = t.active ? t.position_ws : end.ankles[static_cast<std::size_t>(i)];
    EXPECT_LT(horizontal(at, end.ankles[static_cast<std::size_t>(i)]), params.step_trigger_m + 1e-9);
  }
}

TEST(FootHold, StartsNoHoldOutsideABlendAndLetsGoOnceThePoseCaughtUp) {
  FootHold hold;
  const FootHoldParams params = on();
  const Pose pose(0.0);
  hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {true, true}, false, false,
              params, kDt);
  EXPECT_FALSE(hold.target(0).active);
  EXPECT_FALSE(hold.held(0) || hold.held(1));
  // A blend holds them; when it ends with the pose still where the feet are, they are let go.
  hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {true, true}, true, true, params,
              kDt);
  EXPECT_TRUE(hold.held(0) && hold.held(1));
  EXPECT_TRUE(hold.target(0).active);
  EXPECT_LT((hold.target(0).position_ws - pose.ankles[0]).norm(), 1e-12);  // holding moves nothing
  hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {true, true}, false, false,
              params, kDt);
  EXPECT_FALSE(hold.held(0) || hold.held(1));
}

TEST(FootHold, AFootTheNewFrameHasInTheAirStepsFromWhereItStood) {
  FootHold hold;
  const FootHoldParams params = on();
  // At the jump the new frame has the left foot swinging: it is held where it stands and steps.
  Pose pose(0.0);
  hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {false, true}, true, true, params,
              kDt);
  EXPECT_TRUE(hold.stepping(0));
  EXPECT_FALSE(hold.stepping(1));
  EXPECT_TRUE(hold.held(1));
  // The first frame of the step is raised, not moved.
  EXPECT_GT(hold.target(0).position_ws.y(), pose.ankles[0].y());
  EXPECT_LT(horizontal(hold.target(0).position_ws, pose.ankles[0]), 1e-12);
}

TEST(FootHold, AFloorLevelStepWhoseCapturedFootPlantsAgainLiftsInstead) {
  // The left foot is in the air in the new frame: it steps at once, lands while the capture still
  // swings it and follows the pose at floor level; at frame 20 the capture plants it again, far
  // from where the pose has gone. Crossing on along the floor would slide it at the pose's speed
  // (1.8 m/s); it steps instead.
  FootHold hold;
  const FootHoldParams params = on();
  Vec3 previous = Vec3::Zero();
  double highest_after = 0.0;
  for (int f = 0; f < 40; ++f) {
    const Pose pose(f * 0.03);
    const bool planted_again = f >= 20;
    hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {planted_again, true}, true,
                f == 0, params, kDt);
    const FootHoldTarget& t = hold.target(0);
    const Vec3 at = t.active ? t.position_ws : pose.ankles[0];
    if (f == 19) {
      ASSERT_TRUE(hold.stepping(0));  // the step at floor level is under way
      EXPECT_LT(at.y() - 0.08, 1e-9);
    }
    if (planted_again) {
      const double lifted = at.y() - 0.08;
      highest_after = std::max(highest_after, lifted);
      if (lifted < 0.01) {
        EXPECT_LT(horizontal(at, previous) / kDt, 0.3) << "frame " << f;
      }
    }
    previous = at;
  }
  EXPECT_GT(highest_after, 0.5 * params.step_height_m);
}

TEST(FootHold, AHeldFootKeepsItsHeadingWhileThePoseTurns) {
  FootHold hold;
  const FootHoldParams params = on();
  hold.update(Pose(0.0).ankles, Pose(0.0).rotations, Pose(0.0).hips, Pose(0.0).legs,
              {true, true}, true, true, params, kDt);
  const Pose turned(0.0, 0.5);
  hold.update(turned.ankles, turned.rotations, turned.hips, turned.legs, {true, true}, true, false,
              params, kDt);
  ASSERT_TRUE(hold.target(0).active);
  // turn * the pose's rotation = the held rotation (identity).
  const Quat shown = hold.target(0).turn_ws * turned.rotations[0];
  EXPECT_LT(shown.angularDistance(Quat::Identity()), 1e-9);
}

TEST(FootHold, AStepTurnsTheFootBackTheWayTheBodyTurnedOverIt) {
  // The blend turns the body at 6 rad/s over the held feet; the captured right foot lifts at 2.5
  // rad and steps back to the pose's heading while the body turns on past half a turn. The shown
  // heading turns smoothly: the held heading taken the shorter way round flips sign at half a
  // turn, which turned the stepping foot by nearly a full turn in one frame (136 rad/s measured).
  FootHold hold;
  const FootHoldParams params = on();
  Quat previous = Quat::Identity();
  double fastest = 0.0;
  for (int f = 0; f < 90; ++f) {
    const double yaw = std::min(f, 45) * 0.1;
    const Pose pose(0.0, yaw);
    hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {true, f < 25}, true, f == 0,
                params, kDt);
    const FootHoldTarget& t = hold.target(1);
    const Quat shown = t.active ? Quat(t.turn_ws * pose.rotations[1]) : pose.rotations[1];
    if (f > 0) fastest = std::max(fastest, shown.angularDistance(previous));
    previous = shown;
  }
  EXPECT_FALSE(hold.held(1));  // turned back and let go
  // The step turns the foot back by what the body turned over it (2.5 rad and more as the body
  // turns on) over 0.8 of 15 frames along a smoothstep: about 0.46 rad a frame at most. The
  // shorter way round flipped it by 3.1 rad in a frame.
  EXPECT_LT(fastest, 0.6);
}

TEST(FootHold, AFootOutOfReachStepsEvenWhileTheOtherSteps) {
  FootHold hold;
  const FootHoldParams params = on();
  Pose pose(0.0);
  hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {false, true}, true, true, params,
              kDt);
  ASSERT_TRUE(hold.stepping(0));
  ASSERT_FALSE(hold.stepping(1));
  // The body has gone 0.5 m on in one frame (the right foot is now 0.5 m behind its hip: out of
  // reach at 0.9 m height).
  const Pose far(0.5);
  hold.update(far.ankles, far.rotations, far.hips, far.legs, {true, true}, true, false, params,
              kDt);
  EXPECT_TRUE(hold.stepping(1));
}

TEST(FootHold, NonFiniteInputLeavesTheFootAlone) {
  FootHold hold;
  const FootHoldParams params = on();
  Pose pose(0.0);
  hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {true, true}, true, true, params,
              kDt);
  ASSERT_TRUE(hold.held(0));
  pose.ankles[0].x() = std::numeric_limits<double>::quiet_NaN();
  hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {true, true}, true, false,
              params, kDt);
  EXPECT_FALSE(hold.target(0).active);
  EXPECT_FALSE(hold.held(0));
  EXPECT_TRUE(hold.target(1).active);
  EXPECT_TRUE(hold.target(1).position_ws.allFinite());
}

TEST(FootHold, DisabledHoldsNothing) {
  FootHold hold;
  FootHoldParams params;
  params.enabled = false;
  const Pose pose(0.0);
  hold.update(pose.ankles, pose.rotations, pose.hips, pose.legs, {true, true}, true, true, params,
              kDt);
  EXPECT_FALSE(hold.target(0).active || hold.target(1).active);
}

TEST(FootHoldParams, ValidateNamesTheField) {
  FootHoldParams p;
  EXPECT_EQ(p.validate(), "");
  p.step_time_s = -1.0;
  EXPECT_NE(p.validate().find("foot_hold.step_time_s"), std::string::npos);
  p = FootHoldParams{};
  p.step_height_m = std::numeric_limits<double>::infinity();
  EXPECT_NE(p.validate().find("foot_hold.step_height_m"), std::string::npos);
  p = FootHoldParams{};
  p.speed_budget_rad_s = std::numeric_limits<double>::infinity();  // no budget: valid
  EXPECT_EQ(p.validate(), "");
  for (const double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    p.speed_budget_rad_s = bad;
    EXPECT_NE(p.validate().find("foot_hold.speed_budget_rad_s"), std::string::npos) << bad;
    p = FootHoldParams{};
    p.least_speed_rad_s = bad;
    EXPECT_NE(p.validate().find("least_speed_rad_s"), std::string::npos) << bad;
    p = FootHoldParams{};
  }
}

}  // namespace
}  // namespace duet
