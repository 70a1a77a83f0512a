// Issue 13 on real data: the beam follower estimates the same states as the exact step when a
// salsa take is followed through the whole salsa library (27,495 states), while the full step
// runs on few frames.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "duet/follow/beam_follower.h"
#include "duet/follow/hmm_follower.h"
#include "duet/io/motion_file.h"
#include "salsa_library.h"

namespace duet {
namespace {

using test::kSalsaData;

TEST(BeamFollow, EstimatesTheSameStatesAsTheExactStepOnRealTakes) {
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  // Take 01 on the CMU ASF rig (another rig than the library's) and take 05 on the library's own.
  for (const std::vector<std::string>& files :
       {std::vector<std::string>{kSalsaData + "/cmu-salsa/asf-amc/60.asf",
                                 kSalsaData + "/cmu-salsa/asf-amc/60_01.amc"},
        std::vector<std::string>{kSalsaData + "/cmu-salsa/bvh/60/60_05_scaled.bvh"}}) {
    SCOPED_TRACE(files.back());
    Result<LoadedMotion> input = load_motion(files, options);
    ASSERT_TRUE(input) << input.error().message;
    const std::vector<FollowResult> exact = test::follow_clip(input.value());

    Result<BeamFollower> created = BeamFollower::create(test::salsa_library().model(), {});
    ASSERT_TRUE(created) << created.error().message;
    auto beam_follower = std::make_unique<BeamFollower>(std::move(created).value());
    const BeamFollower* beam_view = beam_follower.get();
    // The session owns the follower: it must outlive the reads of beam_view below.
    Result<FollowSession> session =
        FollowSession::create(test::salsa_library(), input.value().clip.skeleton_ptr(),
                              input.value().roles, std::move(beam_follower));
    ASSERT_TRUE(session) << session.error().message;
    const Clip& clip = input.value().clip;
    std::vector<FollowResult> beam;
    for (int f = 0; f < clip.frame_count(); ++f) {
      beam.push_back(session.value().step(clip.translations_ls(f), clip.rotations_ls(f),
                                          f / clip.frame_rate()));
    }

    ASSERT_EQ(exact.size(), beam.size());
    int different = 0;
    for (std::size_t i = 0; i < exact.size(); ++i) {
      if (exact[i].state != beam[i].state) {
        ++different;
        std::printf("frame %zu: exact state %d, beam state %d\n", i, exact[i].state,
                    beam[i].state);
      }
      EXPECT_EQ(exact[i].lost, beam[i].lost) << "frame " << i;
      EXPECT_EQ(exact[i].jumped, beam[i].jumped) << "frame " << i;
      EXPECT_NEAR(exact[i].confidence, beam[i].confidence, 1e-3) << "frame " << i;
    }
    const long long frames = beam_view->context().frames();
    const long long full = beam_view->context().full_steps();
    std::printf("%zu frames, %d with another state, %lld full steps, final beam %d states\n",
                exact.size(), different, full, beam_view->context().beam_size());
    EXPECT_EQ(different, 0);
    // The beam carries the frames: the full step is the first frame and rare fallbacks.
    EXPECT_LT(full * 50, frames);
  }
}

}  // namespace
}  // namespace duet
