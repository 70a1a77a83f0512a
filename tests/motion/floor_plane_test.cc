#include "duet/motion/floor_plane.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "duet/math/rotation.h"

namespace duet {
namespace {

double degrees_between(const Vec3& a, const Vec3& b) {
  return rad_to_deg(std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)));
}

// Toe positions of a dancer on a floor whose normal is `up`: `count` places spread over
// `extent_x` x `extent_z` metres, 1.5 cm of height noise.
std::vector<Vec3> toes_on_floor(const Vec3& up, double extent_x, double extent_z, int count,
                                unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> across(-0.5, 0.5);
  std::normal_distribution<double> height(0.0, 0.015);
  const Quat tilt = Quat::FromTwoVectors(Vec3::UnitY(), up);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i) {
    const Vec3 level(extent_x * across(rng), 0.03 + height(rng), extent_z * across(rng));
    points.push_back(tilt * level + Vec3(2.0, 0.0, -1.0));
  }
  return points;
}

TEST(FloorPlane, ATiltedFloorIsReadFromTheToesWhateverTheBodysLean) {
  const Vec3 floor_up =
      Quat(Eigen::AngleAxisd(deg_to_rad(12.0), Vec3(1, 0, 2).normalized())) * Vec3::UnitY();
  const std::vector<Vec3> points = toes_on_floor(floor_up, 1.2, 1.0, 240, 1);
  // The body's mean up leans 5 degrees off the floor's normal: the floor wins.
  const Vec3 leaning = Quat(Eigen::AngleAxisd(deg_to_rad(5.0), Vec3::UnitZ())) * floor_up;
  const FloorFit fit = fit_floor(points, leaning, 40.0);
  EXPECT_LT(degrees_between(fit.up, floor_up), 1.0);
  EXPECT_NEAR(fit.height_spread_m, 0.015, 0.005);
  EXPECT_NEAR(fit.up.norm(), 1.0, 1e-12);
}

TEST(FloorPlane, WhereTheToesDoNotSpreadThePriorDecides) {
  // A walk along X on a floor sloping along X: the slope along the line is read from the toes,
  // across it the body's mean up (leaning 4 degrees across) decides.
  const Vec3 floor_up = Quat(Eigen::AngleAxisd(deg_to_rad(10.0), Vec3::UnitZ())) * Vec3::UnitY();
  const Vec3 leaning_across =
      Quat(Eigen::AngleAxisd(deg_to_rad(4.0), Vec3::UnitX())) * Vec3::UnitY();
  const std::vector<Vec3> line = toes_on_floor(floor_up, 2.5, 0.0, 240, 2);
  const FloorFit fit = fit_floor(line, leaning_across, 20.0);
  EXPECT_NEAR(-fit.up.x() / fit.up.y(), -floor_up.x() / floor_up.y(), 0.01) << "along";
  EXPECT_NEAR(-fit.up.z() / fit.up.y(), -leaning_across.z() / leaning_across.y(), 0.02)
      << "across (the level floor's slope is 0, the prior's 0.07)";
  // Dancing on the spot on a level floor: about the prior (4 degrees off the floor).
  const std::vector<Vec3> spot = toes_on_floor(Vec3::UnitY(), 0.0, 0.0, 240, 3);
  EXPECT_LT(degrees_between(fit_floor(spot, leaning_across, 20.0).up, leaning_across), 1.0);
}

TEST(FloorPlane, FeetInTheAirAndBadPointsAreSetAside) {
  const Vec3 floor_up = Quat(Eigen::AngleAxisd(deg_to_rad(8.0), Vec3::UnitX())) * Vec3::UnitY();
  std::vector<Vec3> points = toes_on_floor(floor_up, 1.0, 1.0, 200, 4);
  // A tenth of the frames: both feet 20-40 cm up (a jump), all on one side of the room.
  for (int i = 0; i < 24; ++i) points.push_back(Vec3(2.4, 0.2 + 0.008 * i, -1.0 + 0.015 * i));
  points.push_back(Vec3(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0));
  points.push_back(Vec3(0.0, std::numeric_limits<double>::infinity(), 0.0));
  const FloorFit fit = fit_floor(points, Vec3::UnitY(), 30.0);
  EXPECT_LT(degrees_between(fit.up, floor_up), 1.0);
  // Too few points, or a prior that is no direction: the prior, or +Y.
  const Vec3 prior = Vec3(0.1, 1.0, 0.0).normalized();
  EXPECT_LT((fit_floor(std::span(points).first(2), prior, 30.0).up - prior).norm(), 1e-12);
  EXPECT_LT((fit_floor({}, Vec3::Zero(), 30.0).up - Vec3::UnitY()).norm(), 1e-12);
}

TEST(FloorPlane, AHeadsDipsAreSetAsideBelowItsPath) {
  // A head's path 1.5 m above a floor tilted 8 degrees, and a tenth of the frames a bend held at
  // one end of the room, 40-50 cm lower: the outliers are below the plane, not above it.
  const Vec3 floor_up = Quat(Eigen::AngleAxisd(deg_to_rad(8.0), Vec3::UnitX())) * Vec3::UnitY();
  std::vector<Vec3> path = toes_on_floor(floor_up, 1.2, 1.2, 216, 5);
  for (Vec3& p : path) p += 1.5 * floor_up;
  const Quat tilt = Quat::FromTwoVectors(Vec3::UnitY(), floor_up);
  for (int i = 0; i < 24; ++i) {
    path.push_back(tilt * Vec3(0.1 + 0.01 * i, 1.05 - 0.004 * i, -0.6) + Vec3(2.0, 0.0, -1.0));
  }
  const FloorFit head = fit_floor(path, Vec3::UnitY(), 40.0, 3.0, PlaneOutliers::kBelow);
  EXPECT_LT(degrees_between(head.up, floor_up), 1.0);
  // Read as toes (outliers above), the bend drew the plane towards it.
  EXPECT_GT(degrees_between(fit_floor(path, Vec3::UnitY(), 40.0).up, floor_up), 5.0);

  // The tilt's standard error: small where the points spread over the room, large where they
  // keep to the spot (and never past the prior's 3 degrees).
  EXPECT_GT(head.tilt_sigma_deg, 0.0);
  EXPECT_LT(head.tilt_sigma_deg, 1.0);
  const FloorFit spot = fit_floor(toes_on_floor(floor_up, 0.05, 0.05, 240, 6), Vec3::UnitY(), 40.0);
  EXPECT_GT(spot.tilt_sigma_deg, 5.0 * head.tilt_sigma_deg);
  EXPECT_LT(spot.tilt_sigma_deg, 3.0);
}

}  // namespace
}  // namespace duet
