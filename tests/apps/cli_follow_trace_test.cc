// `duet follow --trace`: a frame the sensor sent twice reaches the follower as missing, and the
// summary and the trace say so (repeated_frame.h); a sensor that stalls for good is lost, and said.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "apps/run_command.h"

namespace duet {
namespace {

using testing::data_path;
using testing::kSalsaLibrary;
using testing::run_duet;

// Take 60_05's BVH lines and the index of its first frame's line.
struct BvhLines {
  std::vector<std::string> lines;
  std::size_t first_frame = 0;
};
BvhLines read_take_05() {
  std::ifstream in(data_path("cmu-salsa/bvh/60/60_05_scaled.bvh"));
  BvhLines bvh;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("Frame Time", 0) == 0) bvh.first_frame = bvh.lines.size() + 1;
    bvh.lines.push_back(line);
  }
  EXPECT_GT(bvh.lines.size(), bvh.first_frame + 1000);
  return bvh;
}
std::string write_lines(const BvhLines& bvh, const std::string& path) {
  std::ofstream out(path);
  for (const std::string& l : bvh.lines) out << l << '\n';
  return path;
}

// Take 60_05 with its frame 300 replaced by frame 299: the sensor sent a sample again.
std::string write_with_repeated_frame(const std::string& path) {
  BvhLines bvh = read_take_05();
  bvh.lines[bvh.first_frame + 300] = bvh.lines[bvh.first_frame + 299];
  return write_lines(bvh, path);
}

// Take 60_05 whose sensor stalls at frame 200: every later frame is frame 200 again.
std::string write_stalled(const std::string& path) {
  BvhLines bvh = read_take_05();
  for (std::size_t l = bvh.first_frame + 201; l < bvh.lines.size(); ++l)
    bvh.lines[l] = bvh.lines[bvh.first_frame + 200];
  return write_lines(bvh, path);
}

TEST(CliFollowTrace, AStalledSensorIsCarriedOnThenLostAndSaid) {
  // Over 3 s without a new pose is lost (FollowParams::missing_lost_s); most of this input is.
  const std::string input = write_stalled(::testing::TempDir() + "cli_follow_stalled.bvh");
  const auto r = run_duet("follow --library " + kSalsaLibrary + " --input " + input +
                          " --input-fps 60 -o /dev/null");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("stalled: "), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("still: "), std::string::npos) << r.output;  // not standing still
}

TEST(CliFollowTrace, ARepeatedFrameIsMissingInTheTraceAndTheSummary) {
  const std::string input =
      write_with_repeated_frame(::testing::TempDir() + "cli_follow_repeated.bvh");
  const std::string trace = ::testing::TempDir() + "cli_follow_repeated.csv";
  const auto r = run_duet("follow --library " + kSalsaLibrary + " --input " + input +
                          " -o /dev/null --trace " + trace);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("frames without evidence: 1 missing or repeated, 0 outliers set aside"),
            std::string::npos)
      << r.output;
  std::ifstream in(trace);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.substr(line.size() - 45), ",missing,outlier,partly_observed,frame_offset");
  int row = 0, missing_rows = 0, between_rows = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 14u) << line;
    EXPECT_EQ(cells[12], "0");  // a full body is observed whole or not at all
    // Where between frames the dancer is: within the confidence window around template_frame.
    const double between = std::stod(cells[13]);
    EXPECT_LE(std::abs(between), 6.0) << line;
    if (between != 0.0) ++between_rows;
    if (cells[10] == "1") {
      ++missing_rows;
      EXPECT_EQ(row, 300);
      EXPECT_EQ(cells[6], "0");  // missing is not lost
    }
    ++row;
  }
  EXPECT_EQ(missing_rows, 1);
  EXPECT_GT(between_rows, row / 2);  // the posterior is rarely all on one frame
}

}  // namespace
}  // namespace duet
