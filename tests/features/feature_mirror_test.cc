// The features' mirror map (issue 13's mirrored copies): the features of a dance danced with left
// and right swapped are the mirror map applied to the dance's features, on the whole body and on
// head and hands.
#include <gtest/gtest.h>

#include "duet/features/feature_extractor.h"
#include "duet/features/feature_mirror.h"
#include "synthetic_dancer.h"

namespace duet {
namespace {

// The dance mirrored through the body's sagittal plane (x -> -x): every joint takes its mirror
// joint's rotation reflected, the root its reflected position. The synthetic skeleton is
// symmetric, with joint index = role, so this is the same skeleton dancing the mirror image.
Clip mirrored(const Clip& clip) {
  Clip out(clip.skeleton_ptr(), clip.frame_rate(), clip.frame_count());
  for (int f = 0; f < clip.frame_count(); ++f) {
    for (int j = 0; j < clip.joint_count(); ++j) {
      const auto from = static_cast<std::size_t>(mirror_role(static_cast<Role>(j)));
      const Quat& q = clip.rotations_ls(f)[from];
      out.rotations_ls(f)[static_cast<std::size_t>(j)] = Quat(q.w(), q.x(), -q.y(), -q.z());
      const Vec3& t = clip.translations_ls(f)[from];
      out.translations_ls(f)[static_cast<std::size_t>(j)] = Vec3(-t.x(), t.y(), t.z());
    }
  }
  return out;
}

TEST(FeatureMirror, MapsADancesFeaturesToItsMirrorImages) {
  const auto skeleton = testing::make_role_skeleton();
  const Clip dance = testing::make_dance(skeleton, 60.0, 300);
  const Clip mirror_dance = mirrored(dance);
  for (const InputPoints points : {InputPoints::kFullBody, InputPoints::kHeadHands}) {
    SCOPED_TRACE(input_points_name(points));
    FeatureSpec spec;
    spec.input_points = points;
    Result<FeatureExtractor> extractor =
        FeatureExtractor::create(skeleton, testing::daz_roles(*skeleton), spec);
    ASSERT_TRUE(extractor) << extractor.error().message;
    FeatureMatrix features = extractor.value().extract_clip(dance);
    FeatureMatrix mirror_features = extractor.value().extract_clip(mirror_dance);
    const FeatureNormalizer normalizer = FeatureNormalizer::fit(features, spec);
    normalizer.apply(features);
    normalizer.apply(mirror_features);
    Result<std::vector<MirroredDim>> map = feature_mirror(spec, normalizer);
    ASSERT_TRUE(map) << map.error().message;
    ASSERT_EQ(static_cast<int>(map.value().size()), spec.dimension());
    float worst = 0.0f;
    bool any_changed = false;
    for (int f = 0; f < dance.frame_count(); ++f) {
      for (int d = 0; d < spec.dimension(); ++d) {
        const MirroredDim& m = map.value()[static_cast<std::size_t>(d)];
        const float predicted = m.scale * features(f, m.source) + m.offset;
        worst = std::max(worst, std::abs(predicted - mirror_features(f, d)));
        any_changed = any_changed || std::abs(mirror_features(f, d) - features(f, d)) > 0.1f;
      }
    }
    EXPECT_LT(worst, 1e-3f);
    EXPECT_TRUE(any_changed);  // the mirror image is another dance
    // Twice is the identity.
    for (int d = 0; d < spec.dimension(); ++d) {
      const MirroredDim& m = map.value()[static_cast<std::size_t>(d)];
      const MirroredDim& back = map.value()[static_cast<std::size_t>(m.source)];
      EXPECT_EQ(back.source, d);
      EXPECT_NEAR(back.scale * m.scale, 1.0f, 1e-5f);
      EXPECT_NEAR(back.scale * m.offset + back.offset, 0.0f, 1e-4f);
    }
  }
}

TEST(FeatureMirror, RefusesASpecWhoseSegmentHasNoMirrorImage) {
  FeatureSpec spec;
  spec.posture_segments = {{Role::kHips, Role::kChest}, {Role::kLeftShoulder, Role::kLeftElbow}};
  FeatureNormalizer normalizer;
  Result<std::vector<MirroredDim>> map = feature_mirror(spec, normalizer);
  ASSERT_FALSE(map);
  EXPECT_NE(map.error().message.find("left_shoulder -> left_elbow"), std::string::npos)
      << map.error().message;
}

}  // namespace
}  // namespace duet
