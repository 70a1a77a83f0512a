// `--beam` on the command line: `duet follow --beam` follows a salsa take through the library with
// the beam follower; asked of a tracker without a beam mode it stops with a clear message.
#include <gtest/gtest.h>

#include <string>

#include "apps/run_command.h"

namespace duet {
namespace {

using testing::data_path;
using testing::run_duet;

const std::string kLibrary =
    std::string(DUET_TESTDATA_DIR) + "/../../libraries/cmu-salsa.toml --data-dir " DUET_DATA_DIR;

TEST(CliBeam, FollowWithTheBeamFollowsATakeWithoutLosingIt) {
  const std::string out = ::testing::TempDir() + "cli_beam_partner.bvh";
  const auto r = run_duet("follow --library " + kLibrary + " --input " +
                          data_path("cmu-salsa/bvh/60/60_05_scaled.bvh") + " -o " + out +
                          " --beam");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("followed 1678 frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0 lost frames"), std::string::npos) << r.output;
}

TEST(CliBeam, ABeamForATrackerWithoutOneIsRefused) {
  const auto r = run_duet("follow --library " + kLibrary + " --input " +
                          data_path("cmu-salsa/bvh/60/60_05_scaled.bvh") +
                          " -o /dev/null --beam --tracker left-to-right");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--beam: beam mode is for the hmm tracker, not 'left-to-right'"),
            std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace duet
