#include "duet/live/source_neuron.h"

#include <gtest/gtest.h>

#include <random>

#include "duet/io/bvh.h"
#include "duet/math/rotation.h"

namespace duet {
namespace {

// A two-joint skeleton in centimetres, as Axis exports it (channel orders differ per joint).
constexpr const char* kHeader = R"(HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
}
MOTION
Frames: 1
Frame Time: 0.008333
0 0 0 0 0 0 0 0 0
)";

SourceSkeleton neuron_skeleton() {
  BvhReadOptions options;
  options.scale = 0.01;  // offsets in metres, as load_motion gives them
  Result<Clip> clip = parse_bvh(kHeader, "axis.bvh", options);
  EXPECT_TRUE(clip) << clip.error().message;
  SourceSkeleton s;
  s.skeleton = clip.value().skeleton_ptr();
  s.metres_per_unit = 0.01;
  s.frame_rate = 120.0;
  return s;
}

double angle_between(const Quat& a, const Quat& b) { return a.angularDistance(b); }

struct Parsed {
  NeuronParse status;
  std::vector<Vec3> t;
  std::vector<Quat> r;
};

Parsed parse(const NeuronRecordParser& parser, std::string_view record) {
  Parsed p{NeuronParse::kOk, std::vector<Vec3>(3), std::vector<Quat>(3)};
  p.status = parser.parse(record, p.t, p.r);
  return p;
}

TEST(SourceNeuron, ParsesAxisRecordWithAvatarHeader) {
  const NeuronRecordParser parser(neuron_skeleton(), {});
  EXPECT_EQ(parser.expected_values(), 9);
  const Parsed p = parse(parser, "0 Avatar00 1 2 3 90 0 0 10 20 30 ||");
  ASSERT_EQ(p.status, NeuronParse::kOk);
  EXPECT_TRUE(p.t[0].isApprox(Vec3(0.01, 0.02, 0.03)));
  // Root channels list Y X Z: 90 degrees about Y.
  EXPECT_LT(angle_between(p.r[0], quat_from_axis_angle(Vec3::UnitY(), kPi / 2)), 1e-9);
  // Spine: no position channels, so its offset; rotations Z X Y as listed.
  EXPECT_TRUE(p.t[1].isApprox(Vec3(0.0, 0.1, 0.0)));
  const EulerOrder zxy = {Axis::kZ, Axis::kX, Axis::kY};
  const Quat spine = quat_from_euler(Vec3(deg_to_rad(10), deg_to_rad(20), deg_to_rad(30)), zxy);
  EXPECT_LT(angle_between(p.r[1], spine), 1e-9);
}

TEST(SourceNeuron, ParsesPlainMotionLines) {
  const NeuronRecordParser parser(neuron_skeleton(), {});
  EXPECT_EQ(parse(parser, "1 2 3 4 5 6 7 8 9").status, NeuronParse::kOk);
  EXPECT_EQ(parse(parser, "\t+1.5 -2e1 3 4 5 6 7 8 9  ").status, NeuronParse::kOk);
  EXPECT_EQ(parse(parser, "3 Avatar03 1 2 3 4 5 6 7 8 9").status, NeuronParse::kOk);
}

TEST(SourceNeuron, RejectsBadRecords) {
  const NeuronRecordParser parser(neuron_skeleton(), {});
  EXPECT_EQ(parse(parser, "").status, NeuronParse::kEmpty);
  EXPECT_EQ(parse(parser, "   ||").status, NeuronParse::kEmpty);
  EXPECT_EQ(parse(parser, "0 Avatar00 1 2 3 4 5 6 7 8").status, NeuronParse::kWrongCount);
  EXPECT_EQ(parse(parser, "0 Avatar00 1 2 3 4 5 6 7 8 9 10").status, NeuronParse::kWrongCount);
  EXPECT_EQ(parse(parser, "1 2 3 4 5 6 7 8").status, NeuronParse::kWrongCount);
  EXPECT_EQ(parse(parser, "1").status, NeuronParse::kWrongCount);
  EXPECT_EQ(parse(parser, "1 2 3 4 x 6 7 8 9").status, NeuronParse::kBadNumber);
  EXPECT_EQ(parse(parser, "1 2 3 4 5 6 7 8 9x").status, NeuronParse::kBadNumber);
  EXPECT_EQ(parse(parser, "1 2 3 4 5 6 7 8 1e999").status, NeuronParse::kBadNumber);
  EXPECT_EQ(parse(parser, "1 2 3 4 nan 6 7 8 9").status, NeuronParse::kNonFinite);
  EXPECT_EQ(parse(parser, "1 2 3 4 inf 6 7 8 9").status, NeuronParse::kNonFinite);
  EXPECT_EQ(parse(parser, "1 2 3 4 1e300 6 7 8 9").status, NeuronParse::kNonFinite);
  EXPECT_EQ(parse(parser, "x Avatar00 1 2 3 4 5 6 7 8 9").status, NeuronParse::kBadHeader);
  EXPECT_EQ(parse(parser, "Avatar00 1 2 3 4 5 6 7 8 9").status, NeuronParse::kBadNumber);
  // Output buffers smaller than the skeleton: refused, never written out of bounds.
  std::vector<Vec3> t(1);
  std::vector<Quat> r(1);
  EXPECT_NE(parser.parse("1 2 3 4 5 6 7 8 9", t, r), NeuronParse::kOk);
}

TEST(SourceNeuron, SkipsReferenceBone) {
  NeuronStreamOptions options;
  options.reference = true;
  const NeuronRecordParser parser(neuron_skeleton(), options);
  EXPECT_EQ(parser.expected_values(), 15);
  const Parsed p = parse(parser, "0 Avatar00 9 9 9 9 9 9 1 2 3 0 0 0 0 0 0 ||");
  ASSERT_EQ(p.status, NeuronParse::kOk);
  EXPECT_TRUE(p.t[0].isApprox(Vec3(0.01, 0.02, 0.03)));
  EXPECT_EQ(parse(parser, "0 Avatar00 1 2 3 0 0 0 0 0 0 ||").status, NeuronParse::kWrongCount);
}

TEST(SourceNeuron, StreamSplitAnywhere) {
  NeuronSource source(neuron_skeleton(), {}, "test");
  const std::string record = "0 Avatar00 1 2 3 0 0 0 0 0 0 ||";
  std::string stream;
  for (int k = 0; k < 5; ++k) stream += record;  // Axis over TCP: records back to back
  stream += "\r\n0 Avatar00 1 2 3 0 0 0 0 0 0\n";
  const auto now = SteadyClock::now();
  // Feed in chunks of every size from 1 to 7 bytes.
  std::size_t pos = 0;
  for (std::size_t size = 1; pos < stream.size(); size = size % 7 + 1) {
    source.feed(std::string_view(stream).substr(pos, size), now);
    pos += size;
  }
  SourceFrame frame;
  frame.resize(3);
  int frames = 0;
  while (source.poll(now, frame)) {
    ++frames;
    EXPECT_TRUE(frame.translations_ls[0].isApprox(Vec3(0.01, 0.02, 0.03)));
  }
  EXPECT_EQ(frames, 6);
  EXPECT_EQ(source.stats().frames, 6);
  EXPECT_EQ(source.stats().rejected, 0);
}

TEST(SourceNeuron, BadLinesAreCountedAndTheStreamGoesOn) {
  NeuronSource source(neuron_skeleton(), {}, "test");
  const auto t0 = SteadyClock::now();
  source.feed("0 Avatar00 1 2 3 0 0 0 0 0 0 ||", t0);
  source.feed("0 Avatar00 1 2 3 0 0 0 0 0 ||", t0);       // one value short
  source.feed("0 Avatar00 1 2 3 0 0 0 0 0 0 0 ||", t0);   // one too many
  source.feed("0 Avatar00 1 2 3 0 0 zero 0 0 0 ||", t0);  // not a number
  source.feed("0 Avatar00 1 2 3 0 0 nan 0 0 0 ||", t0);   // not finite
  source.feed("\n\n||||\r\n", t0);                        // empty records: ignored
  source.feed("0 Avatar00 4 5 6 0 0 0 0 0 0 ||", t0 + std::chrono::milliseconds(500));
  EXPECT_EQ(source.stats().rejected, 4);
  EXPECT_EQ(source.last_rejection(), NeuronParse::kNonFinite);
  SourceFrame frame;
  frame.resize(3);
  ASSERT_TRUE(source.poll(t0, frame));
  EXPECT_DOUBLE_EQ(frame.time_s, 0.0);
  ASSERT_TRUE(source.poll(t0, frame));
  EXPECT_TRUE(frame.translations_ls[0].isApprox(Vec3(0.04, 0.05, 0.06)));
  EXPECT_NEAR(frame.time_s, 0.5, 1e-9);  // arrival times, from the first frame
  EXPECT_FALSE(source.poll(t0, frame));
}

TEST(SourceNeuron, OverlongRecordIsRejectedWithoutBufferingIt) {
  NeuronStreamOptions options;
  options.max_record_bytes = 256;
  NeuronSource source(neuron_skeleton(), options, "test");
  const auto now = SteadyClock::now();
  const std::string garbage(10000, '7');  // no terminator for 10 kB
  source.feed(garbage, now);
  source.feed(garbage, now);
  source.feed("||0 Avatar00 1 2 3 0 0 0 0 0 0 ||", now);
  EXPECT_EQ(source.stats().rejected, 1);
  EXPECT_EQ(source.last_rejection(), NeuronParse::kTooLong);
  SourceFrame frame;
  frame.resize(3);
  EXPECT_TRUE(source.poll(now, frame));
}

TEST(SourceNeuron, QueueKeepsTheNewestFrames) {
  NeuronStreamOptions options;
  options.queue_frames = 2;
  NeuronSource source(neuron_skeleton(), options, "test");
  const auto now = SteadyClock::now();
  for (int k = 1; k <= 5; ++k) {
    source.feed(std::to_string(k) + " 0 0 0 0 0 0 0 0\n", now);
  }
  EXPECT_EQ(source.stats().dropped, 3);
  SourceFrame frame;
  frame.resize(3);
  ASSERT_TRUE(source.poll(now, frame));
  EXPECT_NEAR(frame.translations_ls[0].x(), 0.04, 1e-12);
  ASSERT_TRUE(source.poll(now, frame));
  EXPECT_NEAR(frame.translations_ls[0].x(), 0.05, 1e-12);
  EXPECT_FALSE(source.poll(now, frame));
}

TEST(SourceNeuron, RandomBytesNeverBreakTheStream) {
  NeuronStreamOptions options;
  options.max_record_bytes = 4096;
  NeuronSource source(neuron_skeleton(), options, "test");
  std::mt19937 random(7);
  const std::string alphabet = "0123456789 .-+eE|\n\rAvatar\tnaif";
  std::string noise(200000, ' ');
  for (char& c : noise) {
    c = random() % 8 == 0 ? static_cast<char>(random() % 256)
                          : alphabet[random() % alphabet.size()];
  }
  const auto now = SteadyClock::now();
  for (std::size_t pos = 0; pos < noise.size();) {
    const std::size_t size = 1 + random() % 1500;
    source.feed(std::string_view(noise).substr(pos, size), now);
    pos += size;
  }
  SourceFrame frame;
  frame.resize(3);
  while (source.poll(now, frame)) {
    for (const Vec3& t : frame.translations_ls) EXPECT_TRUE(t.allFinite());
    for (const Quat& q : frame.rotations_ls) EXPECT_NEAR(q.norm(), 1.0, 1e-9);
  }
  EXPECT_GT(source.stats().rejected, 0);
  source.feed("\n0 Avatar00 1 2 3 0 0 0 0 0 0 ||", now);
  ASSERT_TRUE(source.poll(now, frame));
  EXPECT_TRUE(frame.translations_ls[0].isApprox(Vec3(0.01, 0.02, 0.03)));
}

}  // namespace
}  // namespace duet
