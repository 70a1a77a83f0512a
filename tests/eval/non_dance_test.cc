#include "duet/eval/non_dance.h"

#include <gtest/gtest.h>

#include "features/synthetic_dancer.h"

namespace duet {
namespace {

TEST(LoopedClip, RepeatsTheClipUntilLongEnoughAndWalksOn) {
  const Clip walk = testing::make_dance(testing::make_role_skeleton(), 30.0, 90);  // 3 s
  Vec3 walked = walk.translations_ls(89)[0] - walk.translations_ls(0)[0];
  walked.y() = 0.0;
  const Clip looped = looped_clip(walk, 10.0);
  ASSERT_EQ(looped.frame_count(), 4 * 90);  // 12 s: the first whole number of repeats over 10 s
  EXPECT_DOUBLE_EQ(looped.frame_rate(), 30.0);
  for (int r = 0; r < 4; ++r) {
    for (int f : {0, 45, 89}) {
      const int at = r * 90 + f;
      EXPECT_TRUE(looped.translations_ls(at)[0].isApprox(
          walk.translations_ls(f)[0] + static_cast<double>(r) * walked, 1e-12))
          << at;
      for (int j = 0; j < walk.joint_count(); ++j) {
        const auto i = static_cast<std::size_t>(j);
        EXPECT_EQ(looped.rotations_ls(at)[i].coeffs(), walk.rotations_ls(f)[i].coeffs()) << at;
        if (j > 0) {
          EXPECT_EQ(looped.translations_ls(at)[i], walk.translations_ls(f)[i]) << at;
        }
      }
    }
  }
  // Long enough already: as it is.
  EXPECT_EQ(looped_clip(walk, 3.0).frame_count(), 90);
}

}  // namespace
}  // namespace duet
