#include "duet/motion/forward_kinematics.h"

#include <gtest/gtest.h>

#include "duet/motion/resample.h"

namespace duet {
namespace {

// root -> upper (0.5 up) -> lower (0.4 forward along x)
std::shared_ptr<Skeleton> make_arm() {
  auto s = std::make_shared<Skeleton>();
  s->joints.push_back({"root", -1, Vec3::Zero(), {}, false});
  s->joints.push_back({"upper", 0, Vec3(0, 0.5, 0), {}, false});
  s->joints.push_back({"lower", 1, Vec3(0.4, 0, 0), {}, false});
  return s;
}

TEST(ForwardKinematics, ComposesParentTransforms) {
  auto skeleton = make_arm();
  ASSERT_EQ(skeleton->validate(), "");
  Clip clip(skeleton, 30.0, 1);
  clip.translations_ls(0)[0] = Vec3(1, 0, 2);
  clip.rotations_ls(0)[0] = yaw_rotation(kPi / 2);  // +x turns to -z
  clip.rotations_ls(0)[1] = Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()));  // x -> y
  std::vector<Vec3> positions(3);
  std::vector<Quat> rotations(3);
  forward_kinematics(*skeleton, clip.translations_ls(0), clip.rotations_ls(0), positions,
                     rotations);
  EXPECT_LT((positions[0] - Vec3(1, 0, 2)).norm(), 1e-12);
  EXPECT_LT((positions[1] - Vec3(1, 0.5, 2)).norm(), 1e-12);
  EXPECT_LT((positions[2] - Vec3(1, 0.9, 2)).norm(), 1e-12);
  EXPECT_LT(rotations[2].angularDistance(rotations[0] * clip.rotations_ls(0)[1]), 1e-12);
}

TEST(Skeleton, ValidateRejectsBrokenHierarchies) {
  Skeleton s;
  EXPECT_NE(s.validate(), "");
  s.joints.push_back({"a", -1, Vec3::Zero(), {}, false});
  s.joints.push_back({"a", 0, Vec3::Zero(), {}, false});
  EXPECT_NE(s.validate().find("used twice"), std::string::npos);
  s.joints[1].name = "b";
  s.joints[1].parent = 1;
  EXPECT_NE(s.validate().find("after its parent"), std::string::npos);
  s.joints[1].parent = 0;
  s.joints[1].offset = Vec3(std::nan(""), 0, 0);
  EXPECT_NE(s.validate().find("non-finite"), std::string::npos);
}

TEST(Clip, ScaleLengthsScalesOffsetsAndTranslations) {
  Clip clip(make_arm(), 60.0, 2);
  clip.translations_ls(1)[0] = Vec3(1, 2, 3);
  clip.scale_lengths(2.0);
  EXPECT_LT((clip.skeleton().joints[1].offset - Vec3(0, 1.0, 0)).norm(), 1e-12);
  EXPECT_LT((clip.translations_ls(1)[0] - Vec3(2, 4, 6)).norm(), 1e-12);
  EXPECT_LT((clip.translations_ls(0)[2] - Vec3(0.8, 0, 0)).norm(), 1e-12);
}

TEST(Clip, KeepFirstFramesDropsTheRest) {
  Clip clip(make_arm(), 60.0, 5);
  for (int f = 0; f < 5; ++f) clip.translations_ls(f)[0] = Vec3(f, 0, 0);
  clip.keep_first_frames(9);  // more than it has: unchanged
  EXPECT_EQ(clip.frame_count(), 5);
  clip.keep_first_frames(3);
  ASSERT_EQ(clip.frame_count(), 3);
  EXPECT_EQ(clip.translations_ls(2)[0], Vec3(2, 0, 0));
  EXPECT_EQ(clip.rotations_ls(2).size(), static_cast<std::size_t>(clip.joint_count()));
}

TEST(Resample, HalvesTheRateWithSlerp) {
  Clip clip(make_arm(), 60.0, 5);
  for (int f = 0; f < 5; ++f) {
    clip.rotations_ls(f)[1] = Quat(Eigen::AngleAxisd(0.1 * f, Vec3::UnitZ()));
    clip.translations_ls(f)[0] = Vec3(0.01 * f, 0, 0);
  }
  const Clip slow = resample(clip, 30.0);
  ASSERT_EQ(slow.frame_count(), 3);
  EXPECT_DOUBLE_EQ(slow.frame_rate(), 30.0);
  EXPECT_LT(slow.rotations_ls(1)[1].angularDistance(clip.rotations_ls(2)[1]), 1e-12);
  const Clip fast = resample(clip, 120.0);
  ASSERT_EQ(fast.frame_count(), 9);
  EXPECT_LT(fast.rotations_ls(1)[1].angularDistance(Quat(Eigen::AngleAxisd(0.05, Vec3::UnitZ()))),
            1e-12);
  EXPECT_LT((fast.translations_ls(3)[0] - Vec3(0.015, 0, 0)).norm(), 1e-12);
}

}  // namespace
}  // namespace duet
