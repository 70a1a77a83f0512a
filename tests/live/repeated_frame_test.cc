// RepeatedFrameDetector: a pose sent again bit for bit is a repeat, as often as it is sent.
#include "duet/live/repeated_frame.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace duet {
namespace {

struct Pose {
  std::vector<Vec3> t;
  std::vector<Quat> r;
};

Pose pose(double x) {
  return {{Vec3(x, 1.0, 0.0), Vec3(0.0, x, 0.5)},
          {Quat(Eigen::AngleAxisd(x, Vec3::UnitY())), Quat::Identity()}};
}

TEST(RepeatedFrameDetector, EveryCopyOfTheLastPoseIsARepeat) {
  RepeatedFrameDetector detector(2);
  const Pose a = pose(0.1), b = pose(0.2);
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));  // nothing before it
  EXPECT_TRUE(detector.is_repeat(a.t, a.r));   // sent again
  EXPECT_TRUE(detector.is_repeat(a.t, a.r));   // and again: a stalled sensor
  EXPECT_TRUE(detector.is_repeat(a.t, a.r));
  EXPECT_FALSE(detector.is_repeat(b.t, b.r));
  EXPECT_TRUE(detector.is_repeat(b.t, b.r));
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));
}

TEST(RepeatedFrameDetector, APointTrackedOnItsOwnStallsOnItsOwn) {
  // Joint 1 is a controller: held where last seen while joint 0 moves on, the frame is a repeat.
  RepeatedFrameDetector detector(2, {1, 7, -1});  // joints it does not have are left out
  Pose a = pose(0.1);
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));
  a.t[0].x() += 0.01;  // the head moves, the controller holds
  EXPECT_TRUE(detector.is_repeat(a.t, a.r));
  EXPECT_FALSE(detector.whole_pose_repeated());
  EXPECT_TRUE(detector.point_repeated(0));  // which one: its place in the list
  EXPECT_FALSE(detector.point_repeated(1));
  EXPECT_FALSE(detector.point_repeated(2));
  a.t[0].x() += 0.01;
  EXPECT_TRUE(detector.is_repeat(a.t, a.r));
  EXPECT_TRUE(detector.is_repeat(a.t, a.r));  // the whole pose again
  EXPECT_TRUE(detector.whole_pose_repeated());
  a.r[1] = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX()));  // seen again
  a.t[0].x() += 0.01;
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));
  EXPECT_FALSE(detector.whole_pose_repeated());
  EXPECT_FALSE(detector.point_repeated(0));
  // Without tracked points (a full body: joints no one moves are never sent otherwise), a joint
  // held is no repeat.
  RepeatedFrameDetector body(2);
  Pose b = pose(0.2);
  EXPECT_FALSE(body.is_repeat(b.t, b.r));
  b.t[0].x() += 0.01;
  EXPECT_FALSE(body.is_repeat(b.t, b.r));
}

TEST(RepeatedFrameDetector, AnyDifferenceIsANewFrame) {
  RepeatedFrameDetector detector(2);
  Pose a = pose(0.3);
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));
  a.t[1].z() = std::nextafter(a.t[1].z(), 1.0);  // one bit in one joint
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));
  a.r[0].w() = std::nextafter(a.r[0].w(), 0.0);
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));
}

TEST(RepeatedFrameDetector, NaNPosesAndOtherSizesAreNeverRepeatsAndResetForgets) {
  RepeatedFrameDetector detector(2);
  Pose n = pose(0.4);
  n.t[0].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(detector.is_repeat(n.t, n.r));
  EXPECT_FALSE(detector.is_repeat(n.t, n.r));  // NaN never equals itself
  const Pose a = pose(0.5);
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));
  const std::vector<Vec3> one = {Vec3::Zero()};
  const std::vector<Quat> one_r = {Quat::Identity()};
  EXPECT_FALSE(detector.is_repeat(one, one_r));  // another skeleton's pose
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));
  detector.reset();
  EXPECT_FALSE(detector.is_repeat(a.t, a.r));
}

}  // namespace
}  // namespace duet
