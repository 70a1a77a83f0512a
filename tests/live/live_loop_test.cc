#include "duet/live/live_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

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

// Follows take 0 for 5 s, then one second of a pose no dance has (every joint turned a quarter
// turn), and returns the partner's frame for each frame of that second.
std::vector<LiveOutput> lost_second(const PartnerParams& params) {
  LiveLoop loop = make_loop(params);
  const Clip& user = fixture().user.clip;
  for (int f = 0; f < 300; ++f) loop.step(frame_of(user, f));
  const Quat contorted(Eigen::AngleAxisd(1.57, Vec3::UnitX()));
  std::vector<LiveOutput> outputs;
  for (int f = 300; f < 360; ++f) {
    SourceFrame frame = frame_of(user, f);
    for (std::size_t j = 1; j < frame.rotations_ls.size(); ++j) frame.rotations_ls[j] = contorted;
    outputs.push_back(loop.step(frame));
  }
  return outputs;
}

TEST(LiveLoop, WhileTheFollowerIsLostThePartnerDancesOnByItself) {
  // The follower is lost and its maximum wanders. After the first 0.1 s
  // (PlayheadParams::coast_after_lost_s) the partner goes on from where it is, a frame at a time.
  const std::vector<LiveOutput> outputs = lost_second(PartnerParams{});
  int lost = 0;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const LiveOutput& out = outputs[i];
    ASSERT_TRUE(all_finite(out)) << "frame " << i;
    EXPECT_EQ(out.partner_take, 0);
    if (out.follow.lost) ++lost;
    if (i > 10) {
      EXPECT_FALSE(out.follow.jumped) << "frame " << i;
      EXPECT_GE(out.partner_frame - outputs[i - 1].partner_frame, 0) << "frame " << i;
      EXPECT_LE(out.partner_frame - outputs[i - 1].partner_frame, 2) << "frame " << i;
    }
  }
  EXPECT_GE(lost, 50);
  // At the dancer's tempo, about 1.
  EXPECT_NEAR(outputs.back().partner_frame - outputs[10].partner_frame, 49, 6);

  // Coasting from the first lost frame, the partner dances on from where the dancer was lost;
  // never coasting, it follows the estimate to wherever it wanders.
  const auto far_moves = [](const std::vector<LiveOutput>& run) {
    int moves = 0;
    for (std::size_t i = 1; i < run.size(); ++i) {
      if (std::abs(run[i].partner_frame - run[i - 1].partner_frame) > 6) ++moves;
    }
    return moves;
  };
  PartnerParams at_once;
  at_once.playhead.coast_after_lost_s = 0.0;
  const std::vector<LiveOutput> coasted = lost_second(at_once);
  EXPECT_EQ(far_moves(coasted), 0);
  EXPECT_NEAR(coasted.back().partner_frame, 359, 6);
  PartnerParams never;
  never.playhead.coast_after_lost_s = std::numeric_limits<double>::infinity();
  EXPECT_GT(far_moves(lost_second(never)), 0);
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

  // A height calibration is the user's body, not the session's: a reset keeps it; one out of a
  // person's range is refused and changes nothing.
  EXPECT_EQ(loop.head_height_m(), 0.0);
  EXPECT_TRUE(loop.set_head_height(1.52));
  EXPECT_FALSE(loop.set_head_height(152.0));
  EXPECT_FALSE(loop.set_head_height(std::nan("")));
  loop.reset();
  EXPECT_EQ(loop.head_height_m(), 1.52);
  EXPECT_TRUE(all_finite(loop.step(frame_of(user, 1))));
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
