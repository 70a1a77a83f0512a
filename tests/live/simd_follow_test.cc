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

namespace duet {
namespace {

const std::string kData = DUET_DATA_DIR;

const DuetLibrary& library() {
  static const DuetLibrary loaded = [] {
    std::vector<PairFiles> pairs;
    for (const char* trial :
         {"01", "02", "03", "04", "05", "06", "07", "09", "10", "11", "12", "13", "14", "15"}) {
      pairs.push_back({{kData + "/cmu-salsa/bvh/60/60_" + trial + "_scaled.bvh"},
                       {kData + "/cmu-salsa/bvh/61/61_" + trial + "_scaled.bvh"}});
    }
    LibraryOptions options;
    options.load.frame_rate = 60.0;
    Result<DuetLibrary> l = DuetLibrary::load(pairs, options);
    if (!l) throw std::runtime_error(l.error().message);
    return std::move(l).value();
  }();
  return loaded;
}

std::vector<FollowResult> follow(const LoadedMotion& input, SimdLevel level) {
  EXPECT_TRUE(set_simd_level(level));
  Result<HmmFollower> follower = HmmFollower::create(library().model(), FollowParams{});
  EXPECT_TRUE(follower) << follower.error().message;
  Result<FollowSession> session =
      FollowSession::create(library(), input.clip.skeleton_ptr(), input.roles,
                            std::make_unique<HmmFollower>(std::move(follower).value()));
  EXPECT_TRUE(session) << session.error().message;
  std::vector<FollowResult> results;
  for (int f = 0; f < input.clip.frame_count(); ++f) {
    results.push_back(session.value().step(
        input.clip.translations_ls(f), input.clip.rotations_ls(f), f / input.clip.frame_rate()));
  }
  return results;
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
       {std::vector<std::string>{kData + "/cmu-salsa/asf-amc/60.asf",
                                 kData + "/cmu-salsa/asf-amc/60_01.amc"},
        std::vector<std::string>{kData + "/cmu-salsa/bvh/60/60_05_scaled.bvh"}}) {
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
