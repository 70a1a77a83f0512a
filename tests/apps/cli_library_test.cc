// The library options on the command line: exit codes and messages (--pair with one file,
// neither --pair nor --library), --library with the shipped file, ASF+AMC pair members.
#include <gtest/gtest.h>

#include <cstdio>

#include "apps/run_command.h"

namespace duet {
namespace {

using testing::data_path;
using testing::run_duet;

const std::string kLibrary = std::string(DUET_TESTDATA_DIR) + "/../../libraries/cmu-salsa.toml";

TEST(CliLibrary, PairWithOneFileIsABadCommandLine) {
  const testing::CommandResult r =
      run_duet("follow --pair " + data_path("cmu-salsa/bvh/60/60_10_scaled.bvh") +
               " --input " + data_path("cmu-salsa/bvh/60/60_10_scaled.bvh"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--pair: takes two files, LEADER and PARTNER; got only"),
            std::string::npos)
      << r.output;
  const testing::CommandResult none = run_duet("eval");
  EXPECT_EQ(none.exit_code, 2) << none.output;
  EXPECT_NE(none.output.find("--library FILE or --pair LEADER PARTNER is required"),
            std::string::npos)
      << none.output;
  const testing::CommandResult lone_asf =
      run_duet("follow --pair " + data_path("cmu-salsa/asf-amc/60.asf") + " " +
               data_path("cmu-salsa/bvh/61/61_01_scaled.bvh") + " --input x.bvh");
  EXPECT_EQ(lone_asf.exit_code, 2) << lone_asf.output;
  EXPECT_NE(lone_asf.output.find("skeleton without motion: give SKELETON.asf+MOTION.amc"),
            std::string::npos)
      << lone_asf.output;
}

TEST(CliLibrary, ImproviseFromTheLibraryFileAndFromAnAsfAmcPair) {
  const std::string out = ::testing::TempDir() + "duet_cli_library_perf.bvh";
  testing::CommandResult r = run_duet("improvise --library " + kLibrary + " --data-dir " +
                                      data_path("") + " --take 9 --mode play -o " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // Take 9 of the file is trial 11 (no trial 08): 2108 frames, at the file's 60 fps.
  EXPECT_NE(r.output.find("2108 frames at 60 fps"), std::string::npos) << r.output;
  r = run_duet("improvise --pair " + data_path("cmu-salsa/asf-amc/60.asf") + "+" +
               data_path("cmu-salsa/asf-amc/60_01.amc") + " " +
               data_path("cmu-salsa/bvh/61/61_01_scaled.bvh") +
               " --fps 60 --take 0 --mode play -o " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("2242 frames at 60 fps"), std::string::npos) << r.output;
  r = run_duet("improvise --library /nonexistent.toml --take 0 -o " + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;  // CLI11's ExistingPath check
  std::remove(out.c_str());
}

}  // namespace
}  // namespace duet
