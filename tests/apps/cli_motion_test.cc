// End-to-end tests of `duet inspect` and `duet convert` on the real CMU files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "apps/run_command.h"

namespace duet::testing {
namespace {

const std::string kLeader = data_path("cmu-salsa/bvh/60/60_01_scaled.bvh");
const std::string kAsf = data_path("cmu-salsa/asf-amc/60.asf");
const std::string kAmc = data_path("cmu-salsa/asf-amc/60_01.amc");

TEST(CliInspect, PrintsJsonForASalsaBvh) {
  const CommandResult r = run_duet("inspect --json --fps 60 " + kLeader);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto doc = nlohmann::json::parse(r.output);
  EXPECT_EQ(doc["frames"], 2242);
  EXPECT_EQ(doc["fps"], 60.0);
  EXPECT_NEAR(doc["duration_s"].get<double>(), 2242 / 60.0, 1e-9);
  EXPECT_EQ(doc["joints"], 43);
  EXPECT_EQ(doc["channels"], 132);
  EXPECT_EQ(doc["convention"], "daz");
  // Standing head height is about 1.14 units = 1.48 m; the dancers stay within a few metres.
  const double top = doc["bounding_box_m"]["max"][1];
  EXPECT_GT(top, 1.4);
  EXPECT_LT(top, 2.2);
}

TEST(CliInspect, ReadsAsfAmcAndTheHandshakeConvention) {
  CommandResult r = run_duet("inspect " + kAsf + " " + kAmc);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cmu-asf"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frames:      2242"), std::string::npos) << r.output;
  r = run_duet("inspect --json " + data_path("cmu-handshake/18_01.bvh"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output)["convention"], "cmu-bvh");
}

TEST(CliInspect, SaysWhenTheRestPoseIsNoStandingBody) {
  // The Bandai rig's rest pose has every bone along one axis: where its head faces must then be
  // read from its motion (three points, retargeting), and inspect says so.
  CommandResult r = run_duet("inspect " + data_path("bandai/dataset-1_walk_normal_001.bvh"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("rest pose:   no standing body"), std::string::npos) << r.output;
  r = run_duet("inspect --json --fps 60 " + kLeader);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output)["rest_pose_stands"], true);
}

TEST(CliInspect, BadInputFailsWithReason) {
  CommandResult r = run_duet("inspect /nonexistent.bvh");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("/nonexistent.bvh"), std::string::npos) << r.output;

  const auto bad = std::filesystem::temp_directory_path() / "duet_cli_bad.bvh";
  {
    std::FILE* f = std::fopen(bad.c_str(), "w");
    std::fputs("HIERARCHY\nROOT hip\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Wrong\n}\n",
               f);
    std::fclose(f);
  }
  r = run_duet("inspect " + bad.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find(bad.string() + ":5:"), std::string::npos) << r.output;
  std::filesystem::remove(bad);

  r = run_duet("inspect --fps -3 " + kLeader);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = run_duet("frobnicate");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(CliConvert, AsfAmcToBvhResampledAndBack) {
  const auto out = std::filesystem::temp_directory_path() / "duet_cli_convert.bvh";
  CommandResult r = run_duet("convert " + kAsf + " " + kAmc + " --input-fps 60 --fps 30 -o " +
                             out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_duet("inspect --json " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto doc = nlohmann::json::parse(r.output);
  EXPECT_EQ(doc["frames"], 1121);  // 2242 frames at 60 Hz span 37.35 s
  EXPECT_EQ(doc["fps"], 30.0);
  EXPECT_NEAR(doc["body_m"]["standing_height"].get<double>(), 1.71, 0.05);  // no --scale needed
  // The pair as one word, as every other command takes it, writes the same file.
  const auto again = std::filesystem::temp_directory_path() / "duet_cli_convert_word.bvh";
  r = run_duet("convert " + kAsf + "+" + kAmc + " --input-fps 60 --fps 30 -o " + again.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream a(out), b(again);
  const std::string first((std::istreambuf_iterator<char>(a)), std::istreambuf_iterator<char>());
  const std::string second((std::istreambuf_iterator<char>(b)), std::istreambuf_iterator<char>());
  EXPECT_EQ(first, second);
  EXPECT_GT(first.size(), 1000u);
  std::filesystem::remove(out);
  std::filesystem::remove(again);
  // A word that is neither a file nor a pair is refused with the reason.
  r = run_duet("convert " + kAsf + "+missing.amc -o " + again.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("missing.amc"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(again));
}

TEST(CliConvert, UnwritableOutputLeavesNothingBehind) {
  const CommandResult r = run_duet("convert " + kLeader + " -o /nonexistent-dir/out.bvh");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("/nonexistent-dir/out.bvh"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace duet::testing
