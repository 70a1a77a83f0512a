#include "duet/live/live_loop.h"

#include <gtest/gtest.h>

#include <cmath>

#include "duet/follow/hmm_follower.h"
#include "duet/live/source_replay.h"

namespace duet {
namespace {

std::string salsa(const std::string& subject, const std::string& trial) {
  return std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/" + subject + "/" + subject + "_" + trial +
         "_scaled.bvh";
}

struct Fixture {
  std::shared_ptr<const DuetLibrary> library;
  LoadedMotion user;
};

const Fixture& fixture() {
  static const Fixture f = [] {
    LibraryOptions options;
    options.load.frame_rate = 60.0;
    Result<DuetLibrary> library =
        DuetLibrary::load({{{salsa("60", "03")}, {salsa("61", "03")}}}, options);
    EXPECT_TRUE(library) << library.error().message;
    MotionLoadOptions load;
    load.frame_rate = 60.0;
    Result<LoadedMotion> user = load_motion({salsa("60", "03")}, load);
    EXPECT_TRUE(user) << user.error().message;
    return Fixture{std::make_shared<const DuetLibrary>(std::move(library).value()),
                   std::move(user).value()};
  }();
  return f;
}

SourceSkeleton user_skeleton() {
  const LoadedMotion& m = fixture().user;
  return {m.clip.skeleton_ptr(), m.roles, m.metres_per_unit, m.clip.frame_rate()};
}

std::unique_ptr<Tracker> tracker() {
  Result<HmmFollower> follower = HmmFollower::create(fixture().library->model(), FollowParams{});
  EXPECT_TRUE(follower) << follower.error().message;
  return std::make_unique<HmmFollower>(std::move(follower).value());
}

LiveLoop make_loop(const PartnerParams& params = {}) {
  Result<LiveLoop> loop = LiveLoop::create(fixture().library, user_skeleton(), tracker(), params);
  EXPECT_TRUE(loop) << loop.error().message;
  return std::move(loop).value();
}

SourceFrame frame_of(const Clip& clip, int f) {
  SourceFrame frame;
  frame.resize(clip.joint_count());
  frame.time_s = f / clip.frame_rate();
  std::ranges::copy(clip.translations_ls(f), frame.translations_ls.begin());
  std::ranges::copy(clip.rotations_ls(f), frame.rotations_ls.begin());
  return frame;
}

bool all_finite(const LiveOutput& out) {
  for (const auto* v :
       {&out.user_positions_ws, &out.partner_positions_ws, &out.partner_translations_ls}) {
    for (const Vec3& p : *v) {
      if (!p.allFinite()) return false;
    }
  }
  for (const auto* v :
       {&out.user_rotations_ws, &out.partner_rotations_ws, &out.partner_rotations_ls}) {
    for (const Quat& q : *v) {
      if (!q.coeffs().allFinite()) return false;
    }
  }
  return true;
}

TEST(LiveLoop, FollowsAReplayedTakeAndAnswersWithThePartner) {
  LiveLoop loop = make_loop();
  const Clip& user = fixture().user.clip;
  const Clip& response = fixture().library->takes()[0].response_motion.clip;
  ASSERT_EQ(loop.partner_skeleton()->joint_count(), response.joint_count());
  int near = 0;
  for (int f = 0; f < 600; ++f) {
    const LiveOutput& out = loop.step(frame_of(user, f));
    ASSERT_EQ(out.seq, f);
    ASSERT_TRUE(all_finite(out)) << "frame " << f;
    ASSERT_EQ(out.user_positions_ws.size(), static_cast<std::size_t>(user.joint_count()));
    ASSERT_EQ(out.partner_positions_ws.size(), static_cast<std::size_t>(response.joint_count()));
    EXPECT_TRUE(out.partner_synthesised);
    if (f >= 60 && std::abs(out.follow.frame_in_take - f) <= 6) ++near;
  }
  // The user dances the template itself: the follower tracks it closely.
  EXPECT_GT(near, 500);
}

TEST(LiveLoop, WithoutCorrectionsThePartnerIsTheCapturedResponse) {
  PartnerParams params;
  for (const std::string_view name : kCorrectionNames)
    ASSERT_TRUE(set_correction(params, name, false));
  LiveLoop loop = make_loop(params);
  const Clip& user = fixture().user.clip;
  const Clip& response = fixture().library->takes()[0].response_motion.clip;
  for (int f = 0; f < 200; ++f) {
    const LiveOutput& out = loop.step(frame_of(user, f));
    const int state = out.follow.frame_in_take;
    ASSERT_GE(state, 0);
    for (int j = 0; j < response.joint_count(); ++j) {
      const auto jj = static_cast<std::size_t>(j);
      ASSERT_TRUE(out.partner_translations_ls[jj].isApprox(response.translations_ls(state)[jj]));
      ASSERT_LT(out.partner_rotations_ls[jj].angularDistance(response.rotations_ls(state)[jj]),
                1e-9);
    }
  }
}

TEST(LiveLoop, SwitchesAndReset) {
  LiveLoop loop = make_loop();
  EXPECT_TRUE(loop.set_correction("contact", false));
  EXPECT_FALSE(loop.params().contact);
  EXPECT_TRUE(correction_enabled(loop.params(), "align"));
  EXPECT_FALSE(correction_enabled(loop.params(), "contact"));
  EXPECT_FALSE(loop.set_correction("sparkle", true));
  const Clip& user = fixture().user.clip;
  for (int f = 0; f < 30; ++f) loop.step(frame_of(user, 900 + f));
  loop.reset();
  const LiveOutput& out = loop.step(frame_of(user, 0));
  EXPECT_EQ(out.seq, 30);  // seq counts every processed frame, across resets
  EXPECT_FALSE(out.follow.jumped);
  EXPECT_TRUE(all_finite(out));
}

TEST(LiveLoop, RefusesASkeletonWithoutRoles) {
  auto bare = std::make_shared<Skeleton>();
  Joint root;
  root.name = "root";
  bare->joints.push_back(root);
  SourceSkeleton user;
  user.skeleton = bare;
  user.roles.joints.fill(-1);  // no joint plays any role
  EXPECT_FALSE(LiveLoop::create(fixture().library, user, tracker()));
}

}  // namespace
}  // namespace duet
