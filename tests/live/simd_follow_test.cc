// Issue 13 on real data: following a salsa take against the whole salsa library (27,495 states)
// gives the same estimated state on every frame whether the follower's kernels run the scalar
// path (DUET_SIMD=scalar) or the AVX2 one the dispatcher picks on this CPU.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "duet/follow/hmm_follower.h"
#include "duet/follow/simd.h"
#include "duet/io/motion_file.h"
#include "duet/live/duet_library.h"
#include "duet/live/follow_session.h"
#include "salsa_library.h"

namespace duet {
namespace {

using test::kSalsaData;

std::vector<FollowResult> follow(const LoadedMotion& input, SimdLevel level) {
  EXPECT_TRUE(set_simd_level(level));
  return test::follow_clip(input);
}

TEST(SimdFollow, TheDispatchedKernelsEstimateTheSameStatesAsTheScalarPathOnRealData) {
  // What DUET_SIMD would not force: the best path this CPU has.
  const char* forced = std::getenv("DUET_SIMD");
  const std::string saved_env = forced != nullptr ? forced : "";
  ::unsetenv("DUET_SIMD");
  const SimdLevel dispatched = detect_simd_level();
  if (forced != nullptr) ::setenv("DUET_SIMD", saved_env.c_str(), 1);
  if (!cpu_supports(SimdLevel::kAvx2)) {
    // No AVX2 on this CPU: the dispatcher must run the scalar path.
    EXPECT_EQ(dispatched, SimdLevel::kScalar);
    EXPECT_FALSE(set_simd_level(SimdLevel::kAvx2));
    EXPECT_EQ(simd_level(), SimdLevel::kScalar);
    return;
  }
  EXPECT_EQ(dispatched, SimdLevel::kAvx2);
  const SimdLevel saved = simd_level();

  // Take 01 on the CMU ASF rig (another rig than the library's) and take 05 on the library's own.
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  int frames = 0, different = 0, different_take = 0;
  for (const std::vector<std::string>& files :
       {std::vector<std::string>{kSalsaData + "/cmu-salsa/asf-amc/60.asf",
                                 kSalsaData + "/cmu-salsa/asf-amc/60_01.amc"},
        std::vector<std::string>{kSalsaData + "/cmu-salsa/bvh/60/60_05_scaled.bvh"}}) {
    Result<LoadedMotion> input = load_motion(files, options);
    ASSERT_TRUE(input) << input.error().message;
    const std::vector<FollowResult> scalar = follow(input.value(), SimdLevel::kScalar);
    const std::vector<FollowResult> fast = follow(input.value(), dispatched);
    ASSERT_EQ(scalar.size(), fast.size());
    for (std::size_t i = 0; i < scalar.size(); ++i) {
      ++frames;
      if (scalar[i].state != fast[i].state) {
        ++different;
        different_take += scalar[i].take != fast[i].take;
        std::printf("%s frame %zu: scalar state %d, %s state %d\n", files.back().c_str(), i,
                    scalar[i].state, to_string(dispatched), fast[i].state);
      }
      EXPECT_EQ(scalar[i].lost, fast[i].lost) << "frame " << i;
    }
  }
  set_simd_level(saved);
  std::printf("%d frames, %d with another state (%d in another take)\n", frames, different,
              different_take);
  // Ties between neighbouring frames may break differently under other rounding; nothing else.
  EXPECT_LE(different, 3);
  EXPECT_EQ(different_take, 0);
}

}  // namespace
}  // namespace duet
