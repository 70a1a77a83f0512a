// A sensor that loses the dancer for a while (an occluded suit, a controller out of view): the
// dancer dances on, and the follower must find them on again where the band has carried it, not
// by a jump through the pause state.
#include <gtest/gtest.h>

#include <cstdlib>

#include "duet/follow/hmm_follower.h"
#include "salsa_library.h"

namespace duet {
namespace {

TEST(TrackingLossFollow, AfterASecondWithoutFramesTheDancerIsFoundAgainWithoutAJump) {
  // Take 01 as the library loaded it (its take 0).
  const LoadedMotion& take = test::salsa_library().takes()[0].template_motion;
  const Clip& clip = take.clip;
  Result<HmmFollower> follower = HmmFollower::create(test::salsa_library().model(), FollowParams{});
  ASSERT_TRUE(follower) << follower.error().message;
  Result<FollowSession> session =
      FollowSession::create(test::salsa_library(), clip.skeleton_ptr(), take.roles,
                            std::make_unique<HmmFollower>(std::move(follower).value()));
  ASSERT_TRUE(session) << session.error().message;

  // Frames 0-599, nothing for one second (frames 600-659), then 660-899.
  int jumps_after_the_gap = 0, off_after_the_gap = 0;
  for (int f = 0; f < 900; ++f) {
    if (f >= 600 && f < 660) continue;
    const FollowResult r =
        session.value().step(clip.translations_ls(f), clip.rotations_ls(f), f / 60.0);
    if (f < 660) continue;
    jumps_after_the_gap += r.jumped ? 1 : 0;
    off_after_the_gap += (r.take != 0 || std::abs(r.frame_in_take - f) > 6) ? 1 : 0;
    if (f == 660) {
      EXPECT_GE(r.steps, 60) << "the band carried the estimate through the gap";
    }
  }
  EXPECT_EQ(jumps_after_the_gap, 0);
  EXPECT_EQ(off_after_the_gap, 0);
}

}  // namespace
}  // namespace duet
