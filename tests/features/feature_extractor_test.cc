#include "duet/features/feature_extractor.h"

#include <gtest/gtest.h>

#include "features/synthetic_dancer.h"

namespace duet {
namespace {

using testing::daz_roles;
using testing::make_dance;
using testing::make_role_skeleton;

class FeatureExtractorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    skeleton_ = make_role_skeleton();
    ASSERT_EQ(skeleton_->validate(), "");
    Result<FeatureExtractor> e = FeatureExtractor::create(skeleton_, daz_roles(*skeleton_), spec_);
    ASSERT_TRUE(e) << e.error().message;
    extractor_.emplace(std::move(e).value());
  }
  FeatureSpec spec_;
  std::shared_ptr<Skeleton> skeleton_;
  std::optional<FeatureExtractor> extractor_;
};

TEST_F(FeatureExtractorTest, OnlineFramesEqualTheBatchExtraction) {
  const Clip clip = make_dance(skeleton_, 60.0, 300);
  const FeatureMatrix batch = extractor_->extract_clip(clip);
  auto context = extractor_->make_context();
  std::vector<float> row(static_cast<std::size_t>(extractor_->dimension()));
  for (int f = 0; f < clip.frame_count(); ++f) {
    extractor_->extract(context, clip.translations_ls(f), clip.rotations_ls(f), f / 60.0, row);
    for (int d = 0; d < extractor_->dimension(); ++d) {
      ASSERT_EQ(row[static_cast<std::size_t>(d)], batch(f, d)) << "frame " << f << " dim " << d;
    }
  }
}

TEST_F(FeatureExtractorTest, DoesNotDependOnPlaceOrFacingInTheRoom) {
  const Clip clip = make_dance(skeleton_, 60.0, 200);
  Clip moved = clip;
  const Quat turn = yaw_rotation(2.1);
  for (int f = 0; f < moved.frame_count(); ++f) {
    moved.translations_ls(f)[0] = turn * clip.translations_ls(f)[0] + Vec3(3, 0, -2);
    moved.rotations_ls(f)[0] = turn * clip.rotations_ls(f)[0];
  }
  const FeatureMatrix a = extractor_->extract_clip(clip);
  const FeatureMatrix b = extractor_->extract_clip(moved);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-4f);
}

TEST_F(FeatureExtractorTest, VelocitiesAreRealSpeedsAtAnyInputRate) {
  // A body gliding forward at 1.5 m/s while it turns: forward speed 1.5 m/s whatever the rate.
  for (double fps : {30.0, 60.0, 120.0}) {
    Clip clip(skeleton_, fps, static_cast<int>(fps));
    for (int f = 0; f < clip.frame_count(); ++f) {
      const double t = f / fps;
      const double yaw = 0.5 * t;
      clip.rotations_ls(f)[0] = yaw_rotation(yaw);
      clip.translations_ls(f)[0] = Vec3(0, 0.9, 0) + 1.5 * t * (yaw_rotation(0.0) * Vec3::UnitZ());
    }
    const FeatureMatrix rows = extractor_->extract_clip(clip);
    const int root = spec_.block_begin(FeatureBlock::kRootVelocity);
    const int last = clip.frame_count() - 1;
    const double yaw = 0.5 * last / fps;
    EXPECT_NEAR(rows(last, root), 1.5 * std::cos(yaw), 0.05) << fps;  // forward
    EXPECT_NEAR(rows(last, root + 3), 0.5, 1e-3) << fps;                // yaw rate
  }
}

TEST_F(FeatureExtractorTest, NanPoseGivesNanFeaturesAndDoesNotPoisonLaterFrames) {
  const Clip clip = make_dance(skeleton_, 60.0, 40);
  const FeatureMatrix clean = extractor_->extract_clip(clip);
  auto context = extractor_->make_context();
  std::vector<float> row(static_cast<std::size_t>(extractor_->dimension()));
  Pose pose;
  for (int f = 0; f < clip.frame_count(); ++f) {
    clip.pose_at(f, pose);
    if (f == 20) pose.rotations_ls[3] = Quat(std::nanf(""), 0, 0, 0);
    extractor_->extract(context, pose.translations_ls, pose.rotations_ls, f / 60.0, row);
    if (f == 20) {
      EXPECT_TRUE(std::isnan(row[0]));
    } else {
      for (float v : row) ASSERT_TRUE(std::isfinite(v)) << "frame " << f;
    }
  }
  // The last frame's features (window 0.1 s = 6 frames, back past frame 20) match the clean run.
  for (int d = 0; d < extractor_->dimension(); ++d) {
    EXPECT_NEAR(row[static_cast<std::size_t>(d)], clean(39, d), 1e-5);
  }
}

TEST_F(FeatureExtractorTest, MissingRoleIsAClearError) {
  JointRoles roles = daz_roles(*skeleton_);
  roles.joints[static_cast<std::size_t>(Role::kLeftWrist)] = -1;
  Result<FeatureExtractor> e = FeatureExtractor::create(skeleton_, roles, spec_);
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message.find("left_wrist"), std::string::npos);
}

TEST(FeatureNormalizer, FloorsTinyDeviationsAndWeighsBlocks) {
  FeatureSpec spec;
  spec.posture_roles = {Role::kSpine};  // 3 + 4 + 4 = 11 dims
  FeatureMatrix raw = FeatureMatrix::Zero(100, spec.dimension());
  for (int f = 0; f < 100; ++f) {
    raw(f, 0) = static_cast<float>(f % 2);  // std 0.5
    raw(f, 1) = 1e-6f * static_cast<float>(f % 2);  // nearly constant: floored
  }
  const FeatureNormalizer n = FeatureNormalizer::fit(raw, spec);
  EXPECT_NEAR(n.scale()[0], spec.posture_weight / (std::sqrt(3.0) * 0.5), 1e-5);
  EXPECT_NEAR(n.scale()[1], spec.posture_weight / (std::sqrt(3.0) * spec.rotation_std_floor_rad),
              1e-4);
  EXPECT_NEAR(n.scale()[spec.block_begin(FeatureBlock::kRootVelocity) + 3],
              spec.root_velocity_weight / (2.0 * spec.yaw_rate_std_floor_radps), 1e-4);
  FeatureMatrix rows = raw;
  n.apply(rows);
  EXPECT_NEAR(rows.col(0).mean(), 0.0f, 1e-5f);
  EXPECT_TRUE(rows.allFinite());
}

}  // namespace
}  // namespace duet
