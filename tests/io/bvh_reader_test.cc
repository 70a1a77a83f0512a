// BVH reader on tiny synthetic fixtures (tests/testdata/bvh) and inline text: channel orders,
// position channels, End Sites, line endings, options, and one test per malformed input.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "duet/io/bvh.h"
#include "duet/motion/forward_kinematics.h"

namespace duet {
namespace {

const std::string kFixtures = std::string(DUET_TESTDATA_DIR) + "/bvh/";

// Rotation matrices written out by hand, independent of duet/math/rotation.
Eigen::Matrix3d rot_x(double deg) {
  const double c = std::cos(deg * kPi / 180), s = std::sin(deg * kPi / 180);
  Eigen::Matrix3d m;
  m << 1, 0, 0, 0, c, -s, 0, s, c;
  return m;
}
Eigen::Matrix3d rot_y(double deg) {
  const double c = std::cos(deg * kPi / 180), s = std::sin(deg * kPi / 180);
  Eigen::Matrix3d m;
  m << c, 0, s, 0, 1, 0, -s, 0, c;
  return m;
}
Eigen::Matrix3d rot_z(double deg) {
  const double c = std::cos(deg * kPi / 180), s = std::sin(deg * kPi / 180);
  Eigen::Matrix3d m;
  m << c, -s, 0, s, c, 0, 0, 0, 1;
  return m;
}
Eigen::Matrix3d rot(char axis, double deg) {
  return axis == 'X' ? rot_x(deg) : axis == 'Y' ? rot_y(deg) : rot_z(deg);
}

void expect_near(const Vec3& actual, const Vec3& expected, double tolerance = 1e-9) {
  EXPECT_NEAR((actual - expected).norm(), 0.0, tolerance)
      << "actual " << actual.transpose() << ", expected " << expected.transpose();
}

Clip must_read(const std::string& path, const BvhReadOptions& options = {}) {
  Result<Clip> clip = read_bvh(path, options);
  EXPECT_TRUE(clip.ok()) << (clip.ok() ? "" : clip.error().message);
  return clip.ok() ? std::move(clip).value() : Clip();
}

// The error message for `text`, or "parsed" if it parses.
std::string parse_error(const std::string& text, const BvhReadOptions& options = {}) {
  Result<Clip> clip = parse_bvh(text, "x.bvh", options);
  return clip.ok() ? "parsed" : clip.error().message;
}

// A small valid file: root with 6 channels, one 3-channel joint, one End Site; 9 values per
// frame. Line numbers: MOTION is line 16, the first motion line 19.
std::string small_file(const std::string& frames_line, const std::string& motion) {
  return "HIERARCHY\n"
         "ROOT hip\n"
         "{\n"
         "\tOFFSET 0 0 0\n"
         "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"
         "\tJOINT knee\n"
         "\t{\n"
         "\t\tOFFSET 0 -1 0\n"
         "\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n"
         "\t\tEnd Site\n"
         "\t\t{\n"
         "\t\t\tOFFSET 0 -1 0\n"
         "\t\t}\n"
         "\t}\n"
         "}\n"
         "MOTION\n" +
         frames_line + "\nFrame Time: 0.5\n" + motion;
}
const std::string kTwoFrames = "1 2 3 0 0 0 10 20 30\n4 5 6 0 0 0 40 50 60\n";
const std::string kTwoFramesLong =
    "1.000000 2.000000 3.000000 0.000000 0.000000 0.000000 10.000000 20.000000 30.000000\n"
    "4.000000 5.000000 6.000000 0.000000 0.000000 0.000000 40.000000 50.000000 60.000000\n";

// ---- Channel orders -------------------------------------------------------------------------

class EulerOrderFixture : public testing::TestWithParam<const char*> {};

TEST_P(EulerOrderFixture, RootRotationMatchesHandComputedMatrix) {
  const std::string order = GetParam();
  std::string lower = order;
  for (char& c : lower) c = static_cast<char>(std::tolower(c));
  const Clip clip = must_read(kFixtures + "order_" + lower + ".bvh");
  ASSERT_EQ(clip.frame_count(), 2);
  ASSERT_EQ(clip.joint_count(), 3);
  EXPECT_EQ(clip.skeleton().joints[0].rotation_order()[0], static_cast<Axis>(order[0] - 'X'));

  // Frame 0: 30, 45, 60 degrees about the listed axes, composed in listed order (intrinsic).
  const Eigen::Matrix3d expected = rot(order[0], 30) * rot(order[1], 45) * rot(order[2], 60);
  const Eigen::Matrix3d actual = clip.rotations_ls(0)[0].toRotationMatrix();
  EXPECT_LT((actual - expected).norm(), 1e-12) << "order " << order << "\n" << actual;
  EXPECT_TRUE(clip.rotations_ls(0)[1].isApprox(Quat::Identity()));
}

TEST_P(EulerOrderFixture, ChildWorldPositionMatchesHandComputedValues) {
  const std::string order = GetParam();
  std::string lower = order;
  for (char& c : lower) c = static_cast<char>(std::tolower(c));
  const Clip clip = must_read(kFixtures + "order_" + lower + ".bvh");
  ASSERT_EQ(clip.frame_count(), 2);
  // Frame 1: 90 degrees about the first axis, 90 about the second; child offset (1, 2, 3).
  // Worked by hand with Rx90 (x,y,z)->(x,-z,y), Ry90 ->(z,y,-x), Rz90 ->(-y,x,z), applying the
  // second rotation first (R = R_first * R_second).
  const std::map<std::string, Vec3> expected = {{"XYZ", {3, 1, 2}},   {"XZY", {-2, -3, 1}},
                                                {"YXZ", {2, -3, -1}}, {"YZX", {3, 1, 2}},
                                                {"ZXY", {3, 1, 2}},   {"ZYX", {-2, 3, -1}}};
  const std::vector<Vec3> world = world_positions(clip);
  expect_near(world[3 + 1], expected.at(order));
}

INSTANTIATE_TEST_SUITE_P(AllSixOrders, EulerOrderFixture,
                         testing::Values("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"));

// ---- Position channels, End Sites, line endings ---------------------------------------------

void check_six_channel_fixture(const Clip& clip) {
  const Skeleton& s = clip.skeleton();
  ASSERT_EQ(s.joint_count(), 6);
  EXPECT_EQ(s.joints[0].name, "hips");
  EXPECT_EQ(s.joints[1].name, "spine");
  EXPECT_EQ(s.joints[2].name, "spine_End");
  EXPECT_EQ(s.joints[3].name, "spine_End2");
  EXPECT_EQ(s.joints[4].name, "leg");
  EXPECT_EQ(s.joints[5].name, "leg_End");
  EXPECT_TRUE(s.joints[2].end_site && s.joints[3].end_site && s.joints[5].end_site);
  EXPECT_EQ(s.joints[2].parent, 1);
  EXPECT_EQ(s.joints[3].parent, 1);
  EXPECT_EQ(s.joints[5].parent, 4);
  EXPECT_TRUE(s.joints[2].channels.empty());
  EXPECT_EQ(s.channel_count(), 15);
  ASSERT_EQ(s.joints[1].channels.size(), 6u);
  EXPECT_EQ(s.joints[1].channels[0], Channel::kZrotation);
  EXPECT_EQ(s.joints[1].channels[1], Channel::kXposition);
  EXPECT_TRUE(s.joints[1].has_position_channels());
  expect_near(s.joints[1].offset, {0, 0.1, 0});  // the rest offset is kept
  ASSERT_EQ(clip.frame_count(), 2);
  EXPECT_DOUBLE_EQ(clip.frame_rate(), 10.0);

  // Frame 0: the position channels are the local translation, not OFFSET + value.
  expect_near(clip.translations_ls(0)[0], {1, 2, 3});
  expect_near(clip.translations_ls(0)[1], {0.5, 0.25, 0.75});
  expect_near(clip.translations_ls(0)[4], {0.1, -0.1, 0});  // no position channels: OFFSET
  const std::vector<Vec3> world = world_positions(clip);
  expect_near(world[1], {1.5, 2.25, 3.75});
  expect_near(world[2], {1.0, 2.25, 3.75});  // Rz(90) * (0, 0.5, 0) = (-0.5, 0, 0)
  expect_near(world[3], {1.5, 2.45, 3.75});  // Rz(90) * (0.2, 0, 0) = (0, 0.2, 0)
  // Frame 1: all of spine's position channels are 0, so it sits at the root.
  expect_near(world[6 + 1], {-1, -2, -3});
  expect_near(world[6 + 5], {-0.9, -2.9, -3});
}

TEST(BvhReader, SixChannelNonRootJointAndTwoEndSitesUnderOneParent) {
  check_six_channel_fixture(must_read(kFixtures + "six_channel_joint.bvh"));
}

TEST(BvhReader, CrlfFixtureReadsLikeLf) {
  std::ifstream in(kFixtures + "six_channel_joint_crlf.bvh", std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  ASSERT_NE(bytes.str().find("\r\n"), std::string::npos) << "fixture lost its CRLF line endings";
  ASSERT_NE(bytes.str().find('\t'), std::string::npos);
  check_six_channel_fixture(must_read(kFixtures + "six_channel_joint_crlf.bvh"));
}

TEST(BvhReader, CrlfErrorsCountLinesLikeLf) {
  std::string text = small_file("Frames: 2", "1 2 3 0 0 0 10 20 30\n4 5 6 0 0 0 40 oops 60\n");
  std::string crlf;
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  EXPECT_EQ(parse_error(crlf),
            "x.bvh:20: expected a number in frame 1 (joint 'knee', Xrotation), found 'oops'");
}

TEST(BvhReader, OldMacCrLineEndings) {
  std::string text = small_file("Frames: 2", kTwoFrames);
  for (char& c : text) c = c == '\n' ? '\r' : c;
  Result<Clip> clip = parse_bvh(text, "x.bvh");
  ASSERT_TRUE(clip.ok()) << clip.error().message;
  EXPECT_EQ(clip.value().frame_count(), 2);
}

TEST(BvhReader, ToleratesMotionLineLayoutAndSpacing) {
  // Values split over lines differently; spaces, tabs, a '+' sign, exponents, ".5" forms.
  const std::string text =
      small_file("Frames:  2", "1 2\n3 0 0 0 10 20 30 4\t5 6\n\n+0 0e0 -.0 4e1 50 60.\n");
  Result<Clip> clip = parse_bvh(text, "x.bvh");
  ASSERT_TRUE(clip.ok()) << clip.error().message;
  expect_near(clip.value().translations_ls(1)[0], {4, 5, 6});
}

TEST(BvhReader, JointNamesWithSpacesAndBraceOnTheSameLine) {
  const std::string text =
      "HIERARCHY\nROOT Left Hip {\n OFFSET 0 0 0\n CHANNELS 3 Xrotation Yrotation Zrotation\n"
      " JOINT a{\n OFFSET 1 0 0 CHANNELS 0 }\n}\nMOTION\nFrames: 1\nFrame Time: 1\n0 0 0\n";
  Result<Clip> clip = parse_bvh(text, "x.bvh");
  ASSERT_TRUE(clip.ok()) << clip.error().message;
  EXPECT_EQ(clip.value().skeleton().joints[0].name, "Left Hip");
  EXPECT_EQ(clip.value().skeleton().joints[1].name, "a");
}

TEST(BvhReader, HeaderValuesMayBeGluedToKeywordsAndUtf8BomIsSkipped) {
  std::string text = "\xEF\xBB\xBF" + small_file("Frames:2", kTwoFrames);
  text.replace(text.find("Frame Time: 0.5"), 15, "Frame Time:0.5");
  Result<Clip> clip = parse_bvh(text, "x.bvh");
  ASSERT_TRUE(clip.ok()) << clip.error().message;
  EXPECT_EQ(clip.value().frame_count(), 2);
  EXPECT_DOUBLE_EQ(clip.value().frame_rate(), 2.0);
}

TEST(BvhReader, ZeroFramesIsAValidEmptyClip) {
  Result<Clip> clip = parse_bvh(small_file("Frames: 0", ""), "x.bvh");
  ASSERT_TRUE(clip.ok()) << clip.error().message;
  EXPECT_EQ(clip.value().frame_count(), 0);
  EXPECT_EQ(clip.value().joint_count(), 3);
}

TEST(BvhReader, FrameRateOverrideAndScale) {
  BvhReadOptions options;
  options.frame_rate = 60.0;
  options.scale = 0.5;
  Result<Clip> clip = parse_bvh(small_file("Frames: 2", kTwoFrames), "x.bvh", options);
  ASSERT_TRUE(clip.ok()) << clip.error().message;
  EXPECT_DOUBLE_EQ(clip.value().frame_rate(), 60.0);
  // Scale applies to offsets and position channels, not to angles.
  expect_near(clip.value().skeleton().joints[1].offset, {0, -0.5, 0});
  expect_near(clip.value().translations_ls(1)[0], {2, 2.5, 3});
  expect_near(clip.value().translations_ls(1)[1], {0, -0.5, 0});
  const Eigen::Matrix3d expected = rot_z(40) * rot_x(50) * rot_y(60);
  EXPECT_LT((clip.value().rotations_ls(1)[1].toRotationMatrix() - expected).norm(), 1e-12);
}

TEST(BvhReader, BadOptionsAreErrors) {
  BvhReadOptions options;
  options.scale = 0.0;
  EXPECT_EQ(parse_error(small_file("Frames: 2", kTwoFrames), options),
            "x.bvh: scale must be positive and finite, got 0.000000");
  options.scale = 1.0;
  options.frame_rate = -1.0;
  EXPECT_EQ(parse_error(small_file("Frames: 2", kTwoFrames), options),
            "x.bvh: frame rate override must be positive and finite, got -1.000000");
}

// ---- Malformed input: each gives "file:line: reason" ----------------------------------------

TEST(BvhReaderErrors, FrameCountBeyondTheLimitIsRejectedBeforeAllocating) {
  EXPECT_EQ(parse_error(small_file("Frames: 1000000000000", kTwoFrames)),
            "x.bvh:17: Frames: 1000000000000 exceeds the limit of 10000000 frames "
            "(BvhReadOptions::max_frames)");
  EXPECT_EQ(parse_error(small_file("Frames: 99999999999999999999999", kTwoFrames)),
            "x.bvh:17: Frames: 99999999999999999999999 is out of range");
}

TEST(BvhReaderErrors, FrameCountLargerThanTheDataCouldHoldIsRejectedBeforeAllocating) {
  BvhReadOptions options;
  options.max_frames = 1'000'000'000'000;
  // 9 values per frame need at least 17 bytes; 40 bytes follow.
  EXPECT_EQ(parse_error(small_file("Frames: 2000000000", kTwoFrames), options),
            "x.bvh:18: Frames: 2000000000 x 9 channels needs at least 35999999999 bytes of motion "
            "data, but only 43 bytes follow (truncated file?)");
}

TEST(BvhReaderErrors, TruncatedFile) {
  const std::string full = small_file("Frames: 2", kTwoFrames);
  EXPECT_EQ(parse_error(full.substr(0, full.size() - 6)),
            "x.bvh:20: motion line has 7 values, expected 9; the motion data ends after 16 of "
            "Frames: 2 x 9 channels = 18 values (truncated file?)");
  EXPECT_EQ(parse_error(small_file("Frames: 3", kTwoFramesLong)),
            "x.bvh:21: motion data ends after 2 frames, but the header says Frames: 3 "
            "(truncated file?)");
  // Cut inside the hierarchy.
  EXPECT_EQ(parse_error(full.substr(0, full.find("End Site"))),
            "x.bvh:10: unbalanced braces: joint 'knee' (opened at line 6) is not closed with '}' "
            "before end of file");
}

TEST(BvhReaderErrors, NonNumberInMotionData) {
  EXPECT_EQ(parse_error(small_file("Frames: 2", "1 2 3 0 0 0 10 20 30\n4 5 6 0 x 0 40 50 60\n")),
            "x.bvh:20: expected a number in frame 1 (joint 'hip', Yrotation), found 'x'");
  EXPECT_EQ(parse_error(small_file("Frames: 2", "1 2 3 0 0 0 10 20 30\n4 5 6 0 1.5e 0 40 50 60\n")),
            "x.bvh:20: expected a number in frame 1 (joint 'hip', Yrotation), found '1.5e'");
  EXPECT_EQ(parse_error(small_file("Frames: 2", "1 2 3 0 0 0 10 20 30\n4,0 5 6 0 0 0 40 50 60\n")),
            "x.bvh:20: expected a number in frame 1 (joint 'hip', Xposition), found '4,0'");
}

TEST(BvhReaderErrors, NanInMotionData) {
  EXPECT_EQ(parse_error(small_file("Frames: 2", "1 2 3 0 0 0 10 20 30\n4 5 6 0 0 0 40 nan 60\n")),
            "x.bvh:20: non-finite value 'nan' in frame 1 (joint 'knee', Xrotation)");
}

TEST(BvhReaderErrors, InfinityInMotionData) {
  EXPECT_EQ(parse_error(small_file("Frames: 2", "-inf 2 3 0 0 0 10 20 30\n4 5 6 0 0 0 40 50 6\n")),
            "x.bvh:19: non-finite value '-inf' in frame 0 (joint 'hip', Xposition)");
  EXPECT_EQ(parse_error(small_file("Frames: 2", "1 2 3 0 0 0 10 20 1e999\n4 5 6 0 0 0 4 5 6\n")),
            "x.bvh:19: non-finite value '1e999' in frame 0 (joint 'knee', Yrotation)");
}

TEST(BvhReaderErrors, UnderflowingValuesReadAsZero) {
  Result<Clip> clip = parse_bvh(small_file("Frames: 1", "1e-400 2 3 0 0 0 10 20 30\n"), "x.bvh");
  ASSERT_TRUE(clip.ok()) << clip.error().message;
  EXPECT_EQ(clip.value().translations_ls(0)[0].x(), 0.0);
}

TEST(BvhReaderErrors, TooManyChannels) {
  std::string text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("CHANNELS 3"), 10, "CHANNELS 7");
  EXPECT_EQ(parse_error(text), "x.bvh:9: CHANNELS 7 in joint 'knee': a joint has 0 to 6 channels");
}

TEST(BvhReaderErrors, ChannelCountDisagreesWithTheNamesListed) {
  std::string text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("CHANNELS 3"), 10, "CHANNELS 2");
  EXPECT_EQ(parse_error(text), "x.bvh:9: CHANNELS 2 in joint 'knee' but the line lists 3 channels");
  text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("CHANNELS 6"), 10, "CHANNELS 5");
  EXPECT_EQ(parse_error(text), "x.bvh:5: CHANNELS 5 in joint 'hip' but the line lists 6 channels");
  text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("CHANNELS 3"), 10, "CHANNELS 4");
  EXPECT_EQ(parse_error(text), "x.bvh:9: CHANNELS 4 in joint 'knee' but the line lists 3 channels");
}

TEST(BvhReaderErrors, TwoRotationChannels) {
  std::string text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("CHANNELS 3 Zrotation Xrotation Yrotation"), 40,
               "CHANNELS 3 Zrotation Xrotation Yposition");
  EXPECT_EQ(parse_error(text),
            "x.bvh:9: joint 'knee' has 2 rotation channels; a joint needs 0 or 3");
}

TEST(BvhReaderErrors, RepeatedChannel) {
  std::string text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("Zrotation Xrotation Yrotation"), 29, "Zrotation Xrotation Zrotation");
  EXPECT_EQ(parse_error(text), "x.bvh:9: channel Zrotation is listed twice in joint 'knee'");
}

TEST(BvhReaderErrors, MotionLineWithTooFewValues) {
  EXPECT_EQ(parse_error(small_file("Frames: 2", "1 2 3 0 0 0 10 20\n4 5 6 0 0 0 40 50 60\n")),
            "x.bvh:19: motion line has 8 values, expected 9; the motion data ends after 17 of "
            "Frames: 2 x 9 channels = 18 values (truncated file?)");
}

TEST(BvhReaderErrors, MotionLineWithTooManyValues) {
  EXPECT_EQ(parse_error(small_file("Frames: 2", "1 2 3 0 0 0 10 20 30\n4 5 6 0 0 0 40 50 60 70\n")),
            "x.bvh:20: motion line has 10 values, expected 9; the motion data has 19 values, 1 "
            "more than Frames: 2 x 9 channels = 18 values");
}

TEST(BvhReaderErrors, ExtraFramesAfterTheDeclaredCount) {
  EXPECT_EQ(parse_error(small_file("Frames: 1", kTwoFrames)),
            "x.bvh:20: extra value '4' after the last frame: the motion data has 18 values (2 "
            "frames), but Frames: 1 x 9 channels = 9 values");
  EXPECT_EQ(parse_error(small_file("Frames: 0", "junk\n")),
            "x.bvh:19: extra value 'junk' after the last frame: the motion data has 1 values (0 "
            "frames), but Frames: 0 x 9 channels = 0 values");
}

TEST(BvhReaderErrors, UnknownChannelName) {
  std::string text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("Xrotation Yrotation"), 9, "Wrotation");
  EXPECT_EQ(parse_error(text),
            "x.bvh:9: unknown channel name 'Wrotation' in joint 'knee' (expected Xposition, "
            "Yposition, Zposition, Xrotation, Yrotation or Zrotation)");
}

TEST(BvhReaderErrors, MissingMotionSection) {
  const std::string full = small_file("Frames: 2", kTwoFrames);
  EXPECT_EQ(parse_error(full.substr(0, full.find("MOTION"))),
            "x.bvh:16: missing MOTION section after the hierarchy");
  EXPECT_EQ(parse_error(full.substr(0, full.find("MOTION")) + "MOTON\n"),
            "x.bvh:16: expected 'MOTION' after the hierarchy, found 'MOTON'");
  EXPECT_EQ(parse_error(full.substr(0, full.find("Frames"))),
            "x.bvh:17: expected 'Frames:', found end of file");
}

TEST(BvhReaderErrors, BinaryGarbage) {
  std::string garbage;
  for (int i = 0; i < 256; ++i) garbage += static_cast<char>((i * 97 + 13) & 0xff);
  // Byte 0 is a lone CR (a line break), byte 29 a LF: the NUL is on line 3.
  EXPECT_EQ(parse_error(garbage), "x.bvh:3: binary data (a NUL byte) in a BVH text file");
  EXPECT_EQ(
      parse_error("\x7f"
                  "ELF\x02\x01\x01"),
      "x.bvh:1: expected 'HIERARCHY' at the start of a BVH file, found '\\x7fELF\\x02\\x01\\x01'");
  std::string text = small_file("Frames: 2", kTwoFrames);
  text[text.find("10 20 30")] = '\x01';
  EXPECT_EQ(parse_error(text),
            "x.bvh:19: expected a number in frame 0 (joint 'knee', Zrotation), found '\\x010'");
}

TEST(BvhReaderErrors, EmptyFile) {
  EXPECT_EQ(parse_error(""), "x.bvh: empty file (expected a BVH file starting with HIERARCHY)");
  EXPECT_EQ(parse_error(" \r\n\t\n"),
            "x.bvh: empty file (expected a BVH file starting with HIERARCHY)");
}

TEST(BvhReaderErrors, MissingFile) {
  Result<Clip> clip = read_bvh("/nonexistent/walk.bvh");
  ASSERT_FALSE(clip.ok());
  EXPECT_EQ(clip.error().message, "/nonexistent/walk.bvh: cannot open: No such file or directory");
  Result<Clip> dir = read_bvh(kFixtures);
  ASSERT_FALSE(dir.ok());
  EXPECT_EQ(dir.error().message, kFixtures + ": cannot read: is a directory");
}

TEST(BvhReaderErrors, UnbalancedBraces) {
  std::string text = small_file("Frames: 2", kTwoFrames);
  text.erase(text.find("\t}\n}\n"), 3);  // drop knee's closing brace
  EXPECT_EQ(parse_error(text),
            "x.bvh:15: unbalanced braces: joint 'hip' (opened at line 2) is not closed with '}' "
            "before 'MOTION'");
  text = small_file("Frames: 2", kTwoFrames);
  text.insert(text.find("MOTION"), "}\n");
  EXPECT_EQ(parse_error(text), "x.bvh:16: unbalanced braces: '}' with no open joint");
  text = small_file("Frames: 2", kTwoFrames);
  text.erase(text.find("\t{\n\t\tOFFSET 0 -1 0"), 3);  // knee's opening brace
  EXPECT_EQ(parse_error(text), "x.bvh:7: expected '{' after JOINT knee, found 'OFFSET'");
}

TEST(BvhReaderErrors, FrameTimeZeroNegativeOrNotFinite) {
  for (const std::string bad : {"0", "-0.01", "nan", "inf", "abc", ""}) {
    std::string text = small_file("Frames: 2", kTwoFrames);
    text.replace(text.find("Frame Time: 0.5"), 15, "Frame Time: " + bad);
    EXPECT_EQ(parse_error(text),
              "x.bvh:18: Frame Time: must be a positive, finite number of seconds, found " +
                  (bad.empty() ? std::string("nothing") : "'" + bad + "'"))
        << bad;
  }
  std::string text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("Frame Time: 0.5"), 15, "Frame Time: 1e-320");
  EXPECT_EQ(parse_error(text),
            "x.bvh:18: Frame Time: 1e-320 is too small (the frame rate is not finite)");
}

TEST(BvhReaderErrors, DuplicateJointNames) {
  std::string text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("JOINT knee"), 10, "JOINT hip");
  EXPECT_EQ(parse_error(text), "x.bvh:6: duplicate joint name 'hip' (first used at line 2)");
  // An End Site's generated name may collide with a joint declared earlier.
  text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("JOINT knee"), 10, "JOINT hip_End");
  text.replace(text.find("\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 -1 0\n\t\t}\n"), 0,
               "\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 -1 0\n\t\t}\n");
  EXPECT_EQ(parse_error(text), "parsed");  // hip_End_End and hip_End_End2: no clash
}

TEST(BvhReaderErrors, MalformedHierarchyDetails) {
  std::string text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("OFFSET 0 -1 0"), 13, "OFFSET 0 -1");
  EXPECT_EQ(parse_error(text), "x.bvh:9: OFFSET of joint 'knee' needs 3 numbers, found 'CHANNELS'");
  text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("OFFSET 0 -1 0"), 13, "OFFSET 0 nan 0");
  EXPECT_EQ(parse_error(text), "x.bvh:8: OFFSET of joint 'knee' has a non-finite value 'nan'");
  text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("JOINT knee"), 10, "JOINT");
  EXPECT_EQ(parse_error(text), "x.bvh:6: JOINT needs a name");
  text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("End Site"), 8, "End Sight");
  EXPECT_EQ(parse_error(text), "x.bvh:10: expected 'End Site', found 'End' followed by 'Sight'");
  text = small_file("Frames: 2", kTwoFrames);
  text.replace(text.find("JOINT knee"), 10, "BONE knee");
  EXPECT_EQ(parse_error(text),
            "x.bvh:6: expected JOINT, End Site or '}' in joint 'hip', found 'BONE'");
  EXPECT_EQ(parse_error("HIERARCHY\nJOINT a\n"),
            "x.bvh:2: expected 'ROOT' after HIERARCHY, found 'JOINT'");
  EXPECT_EQ(parse_error(small_file("Frames: -1", kTwoFrames)),
            "x.bvh:17: Frames: needs a whole number >= 0, found '-1'");
  text = small_file("Frames: 2", kTwoFrames);
  text.insert(text.find("MOTION"), "ROOT b\n");
  EXPECT_EQ(parse_error(text), "x.bvh:16: a second ROOT: only one skeleton per file is supported");
}

TEST(BvhReaderErrors, DeepNestingDoesNotOverflowTheStack) {
  std::string text = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 0\n";
  const int depth = 100000;
  for (int i = 1; i < depth; ++i)
    text += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 0 0\nCHANNELS 0\n";
  const std::string message = parse_error(text);
  EXPECT_TRUE(message.starts_with("x.bvh:" + std::to_string(5 + 4 * (depth - 1) + 1) +
                                  ": unbalanced braces: joint 'j99999' (opened at line"))
      << message;
}

TEST(BvhReaderErrors, ChannelLessSkeletonCannotClaimHugeFrameCounts) {
  std::string text =
      "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 10000000\n"
      "Frame Time: 1\n";
  EXPECT_EQ(parse_error(text),
            "x.bvh:8: Frames: 10000000 x 1 joints is too large for a skeleton with only 0 channels "
            "(at most 1048576 joint-frames when there are more than 4 joints per channel)");
  text = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 3\nFrame Time: 1\n";
  EXPECT_EQ(parse_error(text), "parsed");
}

}  // namespace
}  // namespace duet
