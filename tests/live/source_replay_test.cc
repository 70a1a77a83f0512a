#include "duet/live/source_replay.h"

#include <gtest/gtest.h>

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
