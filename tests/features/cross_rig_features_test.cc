// The same performance on two real rigs: salsa take 01 as CMU captured it (ASF/AMC, 31 joints,
// the ASF's own axes) and as the DAZ-style BVH of the salsa set (43 joints, another rest pose and
// other proportions). Frame i of one is frame i of the other. Their canonical features must agree
// up to the small differences of where each rig puts its joints.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "duet/features/feature_extractor.h"
#include "duet/io/motion_file.h"
#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/retarget.h"

namespace duet {
namespace {

const std::string kSalsa = std::string(DUET_DATA_DIR) + "/cmu-salsa";

struct Rigs {
  LoadedMotion daz;
  LoadedMotion asf;
};

Rigs load_take01() {
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  Result<LoadedMotion> daz = load_motion({kSalsa + "/bvh/60/60_01_scaled.bvh"}, options);
  Result<LoadedMotion> asf =
      load_motion({kSalsa + "/asf-amc/60.asf", kSalsa + "/asf-amc/60_01.amc"}, options);
  EXPECT_TRUE(daz) << daz.error().message;
  EXPECT_TRUE(asf) << asf.error().message;
  return {std::move(daz).value(), std::move(asf).value()};
}

TEST(CrossRigFeatures, TheSameTakeOnTheAsfAndTheDazRigGivesCloseFeatures) {
  const Rigs rigs = load_take01();
  ASSERT_EQ(rigs.daz.clip.frame_count(), rigs.asf.clip.frame_count());
  const FeatureSpec spec;
  Result<FeatureExtractor> daz =
      FeatureExtractor::create(rigs.daz.clip.skeleton_ptr(), rigs.daz.roles, spec);
  Result<FeatureExtractor> asf =
      FeatureExtractor::create(rigs.asf.clip.skeleton_ptr(), rigs.asf.roles, spec);
  ASSERT_TRUE(daz && asf);
  const FeatureMatrix a = daz.value().extract_clip(rigs.daz.clip);
  const FeatureMatrix b = asf.value().extract_clip(rigs.asf.clip);
  // Standardised as the follower sees them (the template's statistics).
  const FeatureNormalizer normalizer = FeatureNormalizer::fit(a, spec);
  FeatureMatrix na = a, nb = b;
  normalizer.apply(na);
  normalizer.apply(nb);
  const Eigen::VectorXf mean_gap = (na - nb).colwise().mean().transpose();
  const Eigen::VectorXf rms_gap =
      ((na - nb).array().square().colwise().mean().sqrt()).transpose();
  for (int d = 0; d < a.cols(); ++d) {
    std::printf("dim %2d: standardised mean gap %+.3f rms %.3f\n", d, mean_gap[d], rms_gap[d]);
  }
  // The squared distance between the two rigs' frames against the distance between the take's
  // own frames 100 ms apart; raw, and once the constant offset between the rigs is taken out (what
  // PostureBias learns online). The rigs must look like the same moment.
  double cross = 0.0, debiased = 0.0, step = 0.0;
  for (int f = 6; f < a.rows(); ++f) {
    cross += (na.row(f) - nb.row(f)).squaredNorm();
    debiased += (na.row(f) - nb.row(f) - mean_gap.transpose()).squaredNorm();
    step += (na.row(f) - na.row(f - 6)).squaredNorm();
  }
  const auto frames = static_cast<double>(a.rows() - 6);
  std::printf("mean squared distance: across rigs %.4f (%.4f without the constant offset), 100 ms "
              "apart on one rig %.4f\n", cross / frames, debiased / frames, step / frames);
  EXPECT_LT(cross, 1.5 * step);
  EXPECT_LT(debiased, 0.5 * step);
}

}  // namespace
}  // namespace duet
