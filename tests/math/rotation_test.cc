#include "duet/math/rotation.h"

#include <gtest/gtest.h>

#include <random>

namespace duet {
namespace {

double quat_angle_between(const Quat& a, const Quat& b) { return a.angularDistance(b); }

TEST(EulerOrder, ParsesPermutationsOnly) {
  EulerOrder order{};
  EXPECT_TRUE(parse_euler_order("ZXY", order));
  EXPECT_EQ(order[0], Axis::kZ);
  EXPECT_EQ(order[1], Axis::kX);
  EXPECT_EQ(order[2], Axis::kY);
  EXPECT_TRUE(parse_euler_order("xyz", order));
  EXPECT_FALSE(parse_euler_order("XXY", order));
  EXPECT_FALSE(parse_euler_order("XY", order));
  EXPECT_FALSE(parse_euler_order("XYW", order));
}

TEST(Euler, ComposesIntrinsicallyInListedOrder) {
  EulerOrder order{};
  ASSERT_TRUE(parse_euler_order("ZXY", order));
  const Vec3 angles(0.3, -0.7, 1.1);
  const Quat expected = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ())) *
                        Quat(Eigen::AngleAxisd(-0.7, Vec3::UnitX())) *
                        Quat(Eigen::AngleAxisd(1.1, Vec3::UnitY()));
  EXPECT_LT(quat_angle_between(quat_from_euler(angles, order), expected), 1e-12);
}

TEST(Euler, RoundTripsEveryOrderIncludingGimbalLock) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-3.1, 3.1);
  for (const char* text : {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"}) {
    EulerOrder order{};
    ASSERT_TRUE(parse_euler_order(text, order));
    for (int trial = 0; trial < 500; ++trial) {
      Vec3 angles(angle(rng), angle(rng), angle(rng));
      if (trial % 50 == 0) angles[1] = (trial % 100 == 0 ? 1 : -1) * kPi / 2;  // gimbal lock
      const Quat q = quat_from_euler(angles, order);
      const Vec3 back = euler_from_quat(q, order);
      EXPECT_LT(quat_angle_between(quat_from_euler(back, order), q), 1e-9)
          << text << " trial " << trial;
      EXPECT_LE(std::abs(back[1]), kPi / 2 + 1e-9);
    }
  }
}

TEST(LogMap, InvertsExpMapAndTakesTheShortArc) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    Vec3 v(n(rng), n(rng), n(rng));
    if (v.norm() > 3.0) v *= 3.0 / v.norm();
    EXPECT_LT((log_map(exp_map(v)) - v).norm(), 1e-9);
    // q and -q are the same rotation: same rotation vector.
    Quat q = exp_map(v);
    Quat minus_q(-q.w(), -q.x(), -q.y(), -q.z());
    EXPECT_LT((log_map(minus_q) - v).norm(), 1e-9);
  }
  EXPECT_LT(log_map(Quat::Identity()).norm(), 1e-15);
  EXPECT_LT((log_map(exp_map(Vec3(1e-9, 0, 0))) - Vec3(1e-9, 0, 0)).norm(), 1e-15);
}

TEST(Heading, IsTheYawOfTheFacingDirection) {
  for (double yaw : {-2.5, -1.0, 0.0, 0.4, 3.0}) {
    EXPECT_NEAR(wrap_angle(heading_yaw(yaw_rotation(yaw)) - yaw), 0.0, 1e-12);
    // Leaning forward or sideways does not change the heading.
    const Quat leaning = yaw_rotation(yaw) * Quat(Eigen::AngleAxisd(0.5, Vec3::UnitX())) *
                         Quat(Eigen::AngleAxisd(-0.3, Vec3::UnitZ()));
    EXPECT_NEAR(wrap_angle(heading_yaw(leaning) - yaw), 0.0, 0.2);
  }
}

TEST(WrapAngle, MapsIntoHalfOpenInterval) {
  EXPECT_NEAR(wrap_angle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(-kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(deg_to_rad(-854.4)), deg_to_rad(-134.4), 1e-12);
}

}  // namespace
}  // namespace duet
