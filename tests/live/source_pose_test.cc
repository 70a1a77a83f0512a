#include "duet/live/source_pose.h"

#include <gtest/gtest.h>

#include <cmath>

#include "duet/io/bvh.h"
#include "duet/math/rotation.h"
#include "duet/motion/head_hands.h"

namespace duet {
namespace {

SourceSkeleton three_joints() {
  Result<Clip> clip = parse_bvh(R"(HIERARCHY
ROOT hip
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT chest
  {
    OFFSET 0 0.5 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 0.3 0
    }
  }
}
MOTION
Frames: 1
Frame Time: 0.016667
0 0 0 0 0 0 0 0 0
)",
                                "pose.bvh");
  EXPECT_TRUE(clip) << clip.error().message;
  SourceSkeleton s;
  s.skeleton = clip.value().skeleton_ptr();
  return s;
}

std::vector<double> identity_rotations(int joints) {
  std::vector<double> r;
  for (int j = 0; j < joints; ++j) r.insert(r.end(), {1.0, 0.0, 0.0, 0.0});
  return r;
}

TEST(SourcePose, AcceptsAPoseAndNormalisesRotations) {
  PoseSource source(three_joints(), {}, "ws");
  std::vector<double> rotations = identity_rotations(3);
  rotations[4] = 0.0;  // chest: 90 degrees about Y, scaled by 1.1
  rotations[5] = 0.0;
  const double h = std::sqrt(0.5) * 1.1;
  rotations[4] = h;
  rotations[6] = h;
  std::string reason;
  const auto now = SteadyClock::now();
  ASSERT_TRUE(source.push(2.5, Vec3(1.0, 0.9, -2.0), rotations, now, reason)) << reason;
  SourceFrame frame;
  frame.resize(3);
  ASSERT_TRUE(source.poll(now, frame));
  EXPECT_DOUBLE_EQ(frame.time_s, 2.5);
  EXPECT_EQ(frame.arrival, now);
  EXPECT_TRUE(frame.translations_ls[0].isApprox(Vec3(1.0, 0.9, -2.0)));
  EXPECT_TRUE(frame.translations_ls[1].isApprox(Vec3(0.0, 0.5, 0.0)));  // the skeleton's offset
  EXPECT_NEAR(frame.rotations_ls[1].norm(), 1.0, 1e-12);
  EXPECT_LT(frame.rotations_ls[1].angularDistance(quat_from_axis_angle(Vec3::UnitY(), kPi / 2)),
            1e-9);
  EXPECT_FALSE(source.poll(now, frame));
  EXPECT_EQ(source.stats().frames, 1);
}

TEST(SourcePose, RejectsBadPoses) {
  PoseSource source(three_joints(), {}, "ws");
  const auto now = SteadyClock::now();
  std::string reason;
  EXPECT_FALSE(source.push(0.0, Vec3::Zero(), identity_rotations(2), now, reason));
  EXPECT_NE(reason.find("one [w, x, y, z] per joint"), std::string::npos) << reason;
  std::vector<double> bad = identity_rotations(3);
  bad[4] = 3.0;  // |q| = 3
  EXPECT_FALSE(source.push(0.0, Vec3::Zero(), bad, now, reason));
  bad[4] = 0.0;  // |q| = 0
  EXPECT_FALSE(source.push(0.0, Vec3::Zero(), bad, now, reason));
  bad[4] = std::nan("");
  EXPECT_FALSE(source.push(0.0, Vec3::Zero(), bad, now, reason));
  EXPECT_FALSE(source.push(0.0, Vec3(std::nan(""), 0, 0), identity_rotations(3), now, reason));
  EXPECT_FALSE(source.push(0.0, Vec3(5000, 0, 0), identity_rotations(3), now, reason));
  EXPECT_FALSE(source.push(INFINITY, Vec3::Zero(), identity_rotations(3), now, reason));
  EXPECT_EQ(source.stats().rejected, 7);
  SourceFrame frame;
  frame.resize(3);
  EXPECT_FALSE(source.poll(now, frame));  // nothing half-written was queued
}

TEST(SourcePose, TimeFromArrivalWhenTheSenderGivesNone) {
  PoseSource source(three_joints(), {}, "ws");
  const auto t0 = SteadyClock::now();
  std::string reason;
  ASSERT_TRUE(source.push(std::nan(""), Vec3::Zero(), identity_rotations(3), t0, reason));
  ASSERT_TRUE(source.push(std::nan(""), Vec3::Zero(), identity_rotations(3),
                          t0 + std::chrono::milliseconds(250), reason));
  SourceFrame frame;
  frame.resize(3);
  ASSERT_TRUE(source.poll(t0, frame));
  EXPECT_DOUBLE_EQ(frame.time_s, 0.0);
  ASSERT_TRUE(source.poll(t0, frame));
  EXPECT_NEAR(frame.time_s, 0.25, 1e-9);
}

TEST(SourcePose, AHeadsetsPointsAreMovedFromTheDevicesToTheJoints) {
  // The headset source takes the devices' offsets out of every xr_pose: the head joint 6 cm
  // behind and below the eyes in the headset's own frame, each wrist 7 cm along its grip's +Y.
  PoseSourceOptions options;
  options.device_offsets = typical_headset_offsets();
  PoseSource source(SourceSkeleton{make_head_hands_skeleton(), head_hands_roles(), 1.0, 72.0},
                    options, "xr");
  // The headset turned 90 degrees left (facing -X), the left grip pointing its +Y down, the
  // right grip the identity.
  const Quat head = yaw_rotation(0.5 * kPi);
  const Quat left = Quat(Eigen::AngleAxisd(kPi, Vec3::UnitX()));
  const std::vector<Vec3> positions = {Vec3(0.0, 1.6, 0.0), Vec3(0.3, 1.0, -0.3),
                                       Vec3(-0.3, 1.0, -0.3)};
  const std::vector<double> orientations = {head.w(), head.x(), head.y(), head.z(),
                                            left.w(), left.x(), left.y(), left.z(),
                                            1.0,      0.0,      0.0,      0.0};
  std::string reason;
  const auto now = SteadyClock::now();
  ASSERT_TRUE(source.push_points(1.0, positions, orientations, now, reason)) << reason;
  SourceFrame frame;
  frame.resize(kHeadHandsJointCount);
  ASSERT_TRUE(source.poll(now, frame));
  // Facing -X, the head joint is 6 cm behind the eyes (+X) and 6 cm below them.
  EXPECT_LT((frame.translations_ls[kPointsHead] - Vec3(0.06, 1.54, 0.0)).norm(), 1e-9);
  EXPECT_LT((frame.translations_ls[kPointsLeftHand] - Vec3(0.3, 0.93, -0.3)).norm(), 1e-9);
  EXPECT_LT((frame.translations_ls[kPointsRightHand] - Vec3(-0.3, 1.07, -0.3)).norm(), 1e-9);
  // The orientations are passed on as sent.
  EXPECT_LT(frame.rotations_ls[kPointsHead].angularDistance(head), 1e-9);
}

}  // namespace
}  // namespace duet
