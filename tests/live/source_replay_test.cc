#include "duet/live/source_replay.h"

#include <gtest/gtest.h>

#include <cmath>

namespace duet {
namespace {

using std::chrono::milliseconds;

// 10 frames at 10 Hz; the root's x is the frame index.
LoadedMotion counting_clip() {
  auto skeleton = std::make_shared<Skeleton>();
  Joint root;
  root.name = "root";
  root.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition,
                   Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
  skeleton->joints.push_back(root);
  LoadedMotion motion;
  motion.clip = Clip(skeleton, 10.0, 10);
  for (int f = 0; f < 10; ++f) motion.clip.translations_ls(f)[0] = Vec3(f, 0, 0);
  return motion;
}

SourceFrame one_joint_frame() {
  SourceFrame frame;
  frame.resize(1);
  return frame;
}

TEST(SourceReplay, DeliversFramesWhenDue) {
  Result<ReplaySource> created = ReplaySource::create(counting_clip(), {}, "count.bvh");
  ASSERT_TRUE(created) << created.error().message;
  ReplaySource& replay = created.value();
  const auto t0 = SteadyClock::now();
  replay.start(t0);
  SourceFrame frame = one_joint_frame();
  EXPECT_EQ(replay.next_due(), t0);
  ASSERT_TRUE(replay.poll(t0, frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 0.0);
  EXPECT_EQ(frame.arrival, t0);
  EXPECT_FALSE(replay.poll(t0 + milliseconds(99), frame));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(100), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 1.0);
  EXPECT_NEAR(frame.time_s, 0.1, 1e-12);
  // Two frames due at once come one per poll, each with its own due time as arrival.
  ASSERT_TRUE(replay.poll(t0 + milliseconds(310), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 2.0);
  EXPECT_EQ(frame.arrival, t0 + milliseconds(200));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(310), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 3.0);
  EXPECT_FALSE(replay.poll(t0 + milliseconds(310), frame));
}

TEST(SourceReplay, EndsOrLoops) {
  ReplaySource once = ReplaySource::create(counting_clip(), {}, "count.bvh").value();
  ReplayOptions loop_options;
  loop_options.loop = true;
  ReplaySource looping = ReplaySource::create(counting_clip(), loop_options, "count.bvh").value();
  const auto t0 = SteadyClock::now();
  once.start(t0);
  looping.start(t0);
  SourceFrame frame = one_joint_frame();
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(once.poll(t0 + milliseconds(100 * k), frame));
    ASSERT_TRUE(looping.poll(t0 + milliseconds(100 * k), frame));
  }
  EXPECT_TRUE(once.finished());
  EXPECT_FALSE(once.next_due().has_value());
  EXPECT_FALSE(once.poll(t0 + milliseconds(5000), frame));
  EXPECT_FALSE(looping.finished());
  ASSERT_TRUE(looping.poll(t0 + milliseconds(1000), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 0.0);  // back to the first frame
  EXPECT_NEAR(frame.time_s, 1.0, 1e-12);         // time goes on
}

TEST(SourceReplay, SpeedAndStart) {
  ReplayOptions options;
  options.speed = 2.0;
  options.start_s = 0.5;
  ReplaySource replay = ReplaySource::create(counting_clip(), options, "count.bvh").value();
  EXPECT_DOUBLE_EQ(replay.source_skeleton().frame_rate, 20.0);
  const auto t0 = SteadyClock::now();
  replay.start(t0);
  SourceFrame frame = one_joint_frame();
  ASSERT_TRUE(replay.poll(t0, frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 5.0);
  ASSERT_TRUE(replay.poll(t0 + milliseconds(50), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 6.0);
}

TEST(SourceReplay, SkipsAheadWhenFarBehind) {
  ReplayOptions options;
  options.loop = true;
  ReplaySource replay = ReplaySource::create(counting_clip(), options, "count.bvh").value();
  const auto t0 = SteadyClock::now();
  replay.start(t0);
  SourceFrame frame = one_joint_frame();
  ASSERT_TRUE(replay.poll(t0, frame));
  // Stalled for 2.05 s: the frame due now comes next, the 19 in between are dropped.
  ASSERT_TRUE(replay.poll(t0 + milliseconds(2050), frame));
  EXPECT_EQ(replay.stats().dropped, 19);
  EXPECT_NEAR(frame.time_s, 2.0, 1e-12);
  EXPECT_EQ(frame.translations_ls[0].x(), 0.0);  // frame 20 of a looping 10-frame clip
}

TEST(SourceReplay, PauseHoldsTheNextFrameAndTheClock) {
  ReplaySource replay = ReplaySource::create(counting_clip(), {}, "count.bvh").value();
  const auto t0 = SteadyClock::now();
  replay.start(t0);
  SourceFrame frame = one_joint_frame();
  ASSERT_TRUE(replay.poll(t0, frame));  // frame 0
  replay.set_paused(true, t0 + milliseconds(40));
  EXPECT_TRUE(replay.state().paused);
  EXPECT_FALSE(replay.next_due().has_value());  // nothing to wait for while paused
  EXPECT_FALSE(replay.poll(t0 + milliseconds(5000), frame));
  EXPECT_FALSE(replay.finished());
  // Resumed 5 s later: frame 1 still had 60 ms to wait, and its time_s is 0.1 s, not 5.1 s.
  const auto t1 = t0 + milliseconds(5040);
  replay.set_paused(false, t1);
  EXPECT_FALSE(replay.state().paused);
  EXPECT_EQ(replay.next_due(), t1 + milliseconds(60));
  EXPECT_FALSE(replay.poll(t1 + milliseconds(59), frame));
  ASSERT_TRUE(replay.poll(t1 + milliseconds(60), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 1.0);
  EXPECT_NEAR(frame.time_s, 0.1, 1e-9);
  EXPECT_EQ(replay.stats().dropped, 0);  // the pause is no stall to skip
  ASSERT_TRUE(replay.poll(t1 + milliseconds(160), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 2.0);
  EXPECT_NEAR(frame.time_s, 0.2, 1e-9);
}

TEST(SourceReplay, SeekMovesInTheFileWhileTheClockGoesOn) {
  ReplaySource replay = ReplaySource::create(counting_clip(), {}, "count.bvh").value();
  const auto t0 = SteadyClock::now();
  replay.start(t0);
  SourceFrame frame = one_joint_frame();
  ASSERT_TRUE(replay.poll(t0, frame));                      // frame 0
  ASSERT_TRUE(replay.poll(t0 + milliseconds(100), frame));  // frame 1
  ASSERT_TRUE(replay.seek(0.72, t0 + milliseconds(150)));   // nearest frame: 7
  EXPECT_FALSE(replay.poll(t0 + milliseconds(199), frame));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(200), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 7.0);
  EXPECT_NEAR(frame.time_s, 0.2, 1e-9);
  EXPECT_NEAR(replay.state().position_s, 0.7, 1e-9);
  // Backwards, and past either end (clamped into the file).
  ASSERT_TRUE(replay.seek(0.0, t0 + milliseconds(250)));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(300), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 0.0);
  EXPECT_NEAR(frame.time_s, 0.3, 1e-9);
  ASSERT_TRUE(replay.seek(99.0, t0 + milliseconds(350)));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(400), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 9.0);
  EXPECT_TRUE(replay.finished());
  EXPECT_FALSE(replay.seek(std::nan(""), t0 + milliseconds(400)));
  // A finished replay plays again after a seek, from now (no burst of skipped frames).
  const auto t1 = t0 + milliseconds(9000);
  ASSERT_TRUE(replay.seek(-3.0, t1));
  EXPECT_FALSE(replay.finished());
  ASSERT_TRUE(replay.poll(t1, frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 0.0);
  EXPECT_EQ(replay.stats().dropped, 0);
}

TEST(SourceReplay, SeekWhilePausedShowsThatFrameOnce) {
  ReplaySource replay = ReplaySource::create(counting_clip(), {}, "count.bvh").value();
  const auto t0 = SteadyClock::now();
  replay.start(t0);
  SourceFrame frame = one_joint_frame();
  ASSERT_TRUE(replay.poll(t0, frame));
  replay.set_paused(true, t0 + milliseconds(50));
  ASSERT_TRUE(replay.seek(0.5, t0 + milliseconds(1000)));
  EXPECT_EQ(replay.next_due(), t0 + milliseconds(1000));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(1000), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 5.0);
  EXPECT_NEAR(frame.time_s, 0.1, 1e-9);
  EXPECT_FALSE(replay.poll(t0 + milliseconds(2000), frame));  // still paused
  EXPECT_TRUE(replay.state().paused);
  EXPECT_NEAR(replay.state().position_s, 0.5, 1e-9);
  replay.set_paused(false, t0 + milliseconds(3000));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(3000), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 6.0);
  EXPECT_NEAR(frame.time_s, 0.2, 1e-9);
}

TEST(SourceReplay, SpeedChangesTheRateFromTheNextFrame) {
  ReplaySource replay = ReplaySource::create(counting_clip(), {}, "count.bvh").value();
  const auto t0 = SteadyClock::now();
  replay.start(t0);
  SourceFrame frame = one_joint_frame();
  ASSERT_TRUE(replay.poll(t0, frame));
  EXPECT_FALSE(replay.set_speed(0.0, t0));
  EXPECT_FALSE(replay.set_speed(kReplayMaxSpeed * 2, t0));
  EXPECT_FALSE(replay.set_speed(std::nan(""), t0));
  ASSERT_TRUE(replay.set_speed(0.5, t0 + milliseconds(50)));
  EXPECT_DOUBLE_EQ(replay.state().speed, 0.5);
  EXPECT_DOUBLE_EQ(replay.stream_rate(), 5.0);
  // Frame 1 keeps its due time (100 ms); after it, one frame per 200 ms.
  ASSERT_TRUE(replay.poll(t0 + milliseconds(100), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 1.0);
  EXPECT_FALSE(replay.poll(t0 + milliseconds(299), frame));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(300), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 2.0);
  EXPECT_NEAR(frame.time_s, 0.3, 1e-9);
  ASSERT_TRUE(replay.set_speed(2.0, t0 + milliseconds(300)));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(500), frame));
  ASSERT_TRUE(replay.poll(t0 + milliseconds(550), frame));
  EXPECT_EQ(frame.translations_ls[0].x(), 4.0);
  EXPECT_NEAR(frame.time_s, 0.55, 1e-9);
  const ReplayState state = replay.state();
  EXPECT_NEAR(state.duration_s, 1.0, 1e-12);
  EXPECT_FALSE(state.loop);
  EXPECT_NE(replay.describe().find("speed 2"), std::string::npos) << replay.describe();
}

TEST(SourceReplay, RejectsBadOptions) {
  ReplayOptions options;
  options.speed = 0.0;
  EXPECT_FALSE(ReplaySource::create(counting_clip(), options, "count.bvh"));
  options.speed = 1.0;
  options.start_s = 5.0;  // the clip lasts 1 s
  EXPECT_FALSE(ReplaySource::create(counting_clip(), options, "count.bvh"));
}

}  // namespace
}  // namespace duet
