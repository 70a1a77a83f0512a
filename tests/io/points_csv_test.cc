// The three-point CSV (duet/io/points_csv.h): round trip, resampling of uneven samples, and a clear
// error naming the line and column for every kind of bad input.
#include "duet/io/points_csv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "duet/math/rotation.h"
#include "duet/motion/head_hands.h"
#include "duet/motion/up_axis.h"

namespace duet {
namespace {

// One CSV line: time, then per point a position and a quaternion (x, y, z, w).
std::string line(double t, double head_y, double left_x, const Quat& head_q = Quat::Identity()) {
  return std::to_string(t) + ",0," + std::to_string(head_y) + ",0," + std::to_string(head_q.x()) +
         "," + std::to_string(head_q.y()) + "," + std::to_string(head_q.z()) + "," +
         std::to_string(head_q.w()) + "," + std::to_string(left_x) +
         ",1,0.3,0,0,0,1,-0.3,1,0.3,0,0,0,1\n";
}

std::string error_of(const std::string& text) {
  Result<Clip> clip = parse_points_csv(text, "take.csv");
  return clip ? std::string("(no error)") : clip.error().message;
}

TEST(PointsCsv, RoundTripKeepsEveryPoint) {
  Clip clip(make_head_hands_skeleton(), 72.0, 5);
  for (int f = 0; f < 5; ++f) {
    for (int p = 1; p <= 3; ++p) {
      clip.translations_ls(f)[static_cast<std::size_t>(p)] = Vec3(0.1 * p, 1.0 + 0.01 * f, -0.2 * f);
      clip.rotations_ls(f)[static_cast<std::size_t>(p)] =
          Quat(Eigen::AngleAxisd(0.1 * f + p, Vec3(0.3, 1.0, 0.2).normalized()));
    }
  }
  Result<Clip> back = parse_points_csv(format_points_csv(clip), "round.csv");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_DOUBLE_EQ(back.value().frame_rate(), 72.0);
  ASSERT_EQ(back.value().frame_count(), 5);
  for (int f = 0; f < 5; ++f) {
    for (std::size_t p = 1; p <= 3; ++p) {
      EXPECT_LT((back.value().translations_ls(f)[p] - clip.translations_ls(f)[p]).norm(), 1e-5);
      EXPECT_GT(std::abs(back.value().rotations_ls(f)[p].dot(clip.rotations_ls(f)[p])), 1 - 1e-9);
    }
  }
}

TEST(PointsCsv, AWorldTurnedOnLoadingIsWrittenAsItsPointsAreSeen) {
  // load_motion turns a tilted or Z-up world by its origin joint (turn_world); what is written
  // back (duet convert) is where the points are, not where they sit against the origin.
  Clip clip(make_head_hands_skeleton(), 30.0, 2);
  for (int f = 0; f < 2; ++f) {
    clip.translations_ls(f)[kPointsHead] = Vec3(0.2, 1.6, -0.1 * f);
    clip.rotations_ls(f)[kPointsHead] = Quat(Eigen::AngleAxisd(0.4 * f, Vec3::UnitY()));
  }
  const Quat turn(Eigen::AngleAxisd(deg_to_rad(12.0), Vec3(1.0, 0.0, 2.0).normalized()));
  Clip turned = clip;
  turn_world(turned, turn);
  Result<Clip> back = parse_points_csv(format_points_csv(turned), "turned.csv");
  ASSERT_TRUE(back) << back.error().message;
  for (int f = 0; f < 2; ++f) {
    EXPECT_LT(
        (back.value().translations_ls(f)[kPointsHead] - turn * clip.translations_ls(f)[kPointsHead])
            .norm(),
        1e-5);
    EXPECT_GT(std::abs(back.value().rotations_ls(f)[kPointsHead].dot(
                  turn * clip.rotations_ls(f)[kPointsHead])),
              1 - 1e-9);
  }
}

TEST(PointsCsv, DroppedSamplesAreInterpolatedOnAnEvenGrid) {
  // 10 Hz with the sample at 0.2 s missing: the grid keeps 10 Hz and fills 0.2 s halfway.
  std::string text = points_csv_header() + "\n";
  for (double t : {0.0, 0.1, 0.3, 0.4, 0.5}) text += line(t, 1.5, t);
  Result<Clip> clip = parse_points_csv(text, "gap.csv");
  ASSERT_TRUE(clip) << clip.error().message;
  EXPECT_DOUBLE_EQ(clip.value().frame_rate(), 10.0);
  ASSERT_EQ(clip.value().frame_count(), 6);
  EXPECT_NEAR(clip.value().translations_ls(2)[kPointsLeftHand].x(), 0.2, 1e-6);
  EXPECT_NEAR(clip.value().translations_ls(2)[kPointsHead].y(), 1.5, 1e-9);
}

TEST(PointsCsv, CommentsBlankLinesAndCrLfAreAccepted) {
  const std::string text = "# recorded by a headset\r\n\r\n" + points_csv_header() + "\r\n" +
                           line(0.0, 1.6, 0.1) + "\n" + line(0.0125, 1.6, 0.1);
  Result<Clip> clip = parse_points_csv(text, "crlf.csv");
  ASSERT_TRUE(clip) << clip.error().message;
  EXPECT_DOUBLE_EQ(clip.value().frame_rate(), 80.0);
}

TEST(PointsCsv, BadInputNamesTheLineAndWhatIsWrong) {
  const std::string header = points_csv_header() + "\n";
  EXPECT_NE(error_of("time,x\n" + line(0, 1, 0)).find("take.csv:1: not a three-point CSV"),
            std::string::npos);
  EXPECT_NE(error_of("").find("no header"), std::string::npos);
  EXPECT_NE(error_of(header + line(0, 1, 0)).find("fewer than two samples"), std::string::npos);
  EXPECT_NE(error_of(header + line(0, 1, 0) + "0.1,1,2\n").find("take.csv:3: 3 columns"),
            std::string::npos);
  std::string bad = line(0.1, 1, 0);
  bad.replace(bad.find(",0,"), 3, ",abc,");
  EXPECT_NE(error_of(header + line(0, 1, 0) + bad).find("column 2 (head_x): 'abc'"),
            std::string::npos)
      << error_of(header + line(0, 1, 0) + bad);
  EXPECT_NE(error_of(header + line(0, 1, 0) + line(0, 1, 0)).find("take.csv:3: time_s"),
            std::string::npos);
  EXPECT_NE(error_of(header + line(0, 1, 0) + line(0.1, 1, 0, Quat(0, 0, 0, 0)))
                .find("head orientation has length 0"),
            std::string::npos);
  EXPECT_NE(error_of(header + line(0, 1, 0) + line(0.1, 1, 0) + "nan" + line(0.2, 1, 0).substr(3))
                .find("not a finite number"),
            std::string::npos);
  // Two samples closer than a frame period (found by the fuzzer): no clip of one frame.
  EXPECT_NE(error_of(header + line(0, 1, 0) + line(0.0166, 1, 0)).find("less than two frames"),
            std::string::npos)
      << error_of(header + line(0, 1, 0) + line(0.0166, 1, 0));
  // Times in milliseconds read as a 0.001 Hz rate: said, not allocated.
  EXPECT_NE(error_of(header + line(0, 1, 0) + line(1000, 1, 0)).find("outside 1-1000 Hz"),
            std::string::npos);
}

}  // namespace
}  // namespace duet
