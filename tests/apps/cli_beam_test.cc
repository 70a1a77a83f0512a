// `--beam` on the command line: `duet follow --beam` follows a salsa take through the library with
// the beam follower, also through a library grown with --grow-library and cached with
// --model-cache; asked of a tracker without a beam mode it stops with a clear message.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "apps/run_command.h"

namespace duet {
namespace {

using testing::data_path;
using testing::kSalsaLibrary;
using testing::run_duet;

TEST(CliBeam, FollowWithTheBeamFollowsATakeWithoutLosingIt) {
  const std::string out = ::testing::TempDir() + "cli_beam_partner.bvh";
  const auto r =
      run_duet("follow --library " + kSalsaLibrary + " --input " +
               data_path("cmu-salsa/bvh/60/60_05_scaled.bvh") + " -o " + out + " --beam");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("followed 1678 frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0 lost frames"), std::string::npos) << r.output;
}

// A library grown to 40,000 states (copies of the takes) with the model cache: built on the
// first run, read on the second; take 60_05 is followed at its own frames either way.
TEST(CliBeam, FollowsThroughAGrownLibraryReadFromItsCache) {
  const std::string cache = ::testing::TempDir() + "cli_beam_grown.cache";
  const std::string trace = ::testing::TempDir() + "cli_beam_grown.csv";
  std::remove(cache.c_str());
  for (const bool first : {true, false}) {
    SCOPED_TRACE(first ? "building the cache" : "reading the cache");
    const auto r = run_duet("follow --library " + kSalsaLibrary + " --input " +
                            data_path("cmu-salsa/bvh/60/60_05_scaled.bvh") +
                            " -o /dev/null --beam --grow-library 40000 --model-cache " + cache +
                            " --trace " + trace);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("built the model and wrote the cache") != std::string::npos, first)
        << r.output;
    EXPECT_NE(r.output.find("40000 states: 0 jumps, 0 lost frames"), std::string::npos) << r.output;
    std::ifstream in(trace);
    std::string line;
    std::getline(in, line);  // header: frame,time_s,take,template_frame,...
    int rows = 0, at_own_frame = 0;
    while (std::getline(in, line)) {
      std::stringstream cells(line);
      std::string frame, time, take, template_frame;
      std::getline(cells, frame, ',');
      std::getline(cells, time, ',');
      std::getline(cells, take, ',');
      std::getline(cells, template_frame, ',');
      ++rows;
      // 60_05 is take 4 of the library; within 100 ms (6 frames) of its own frame.
      at_own_frame += take == "4" && std::abs(std::stoi(template_frame) - std::stoi(frame)) <= 6;
    }
    EXPECT_EQ(rows, 1678);
    EXPECT_GE(at_own_frame, 1678 * 99 / 100);
  }
  std::remove(cache.c_str());
  std::remove(trace.c_str());
}

TEST(CliBeam, ABeamForATrackerWithoutOneIsRefused) {
  const auto r = run_duet("follow --library " + kSalsaLibrary + " --input " +
                          data_path("cmu-salsa/bvh/60/60_05_scaled.bvh") +
                          " -o /dev/null --beam --tracker left-to-right");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--beam: beam mode is for the hmm tracker, not 'left-to-right'"),
            std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace duet
