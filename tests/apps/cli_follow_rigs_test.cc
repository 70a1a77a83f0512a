// duet follow with another rig in and out (issue 10): a user on the CMU ASF rig, the partner
// written on the handshake rig, and the exit code that says most of the input was lost.
#include <gtest/gtest.h>

#include <filesystem>

#include "apps/run_command.h"
#include "duet/io/motion_file.h"
#include "duet/motion/body_space.h"

namespace duet {
namespace {

using testing::data_path;
using testing::run_duet;

// Two salsa duets are enough for these checks and keep the test fast.
std::string two_pairs() {
  std::string args;
  for (const char* trial : {"01", "03"}) {
    args += " --pair " + data_path(std::string("cmu-salsa/bvh/60/60_") + trial + "_scaled.bvh") +
            " " + data_path(std::string("cmu-salsa/bvh/61/61_") + trial + "_scaled.bvh");
  }
  return args + " --fps 60";
}

std::filesystem::path temp_file(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("duet_follow_rigs_" + std::to_string(::getpid()) + "_" + name);
}

TEST(CliFollowRigs, AsfInputFollowsAndThePartnerIsWrittenOnAnotherRig) {
  const std::filesystem::path out = temp_file("partner.bvh");
  const std::string input = data_path("cmu-salsa/asf-amc/60.asf") + "+" +
                            data_path("cmu-salsa/asf-amc/60_01.amc");
  const testing::CommandResult r =
      run_duet("follow" + two_pairs() + " --input " + input + " --input-fps 60 -o " +
               out.string() + " --partner-rig " + data_path("cmu-handshake/18_01.bvh"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The partner file has the handshake rig's skeleton and reads back at a person's size.
  Result<LoadedMotion> partner = load_motion({out.string()});
  ASSERT_TRUE(partner) << partner.error().message;
  EXPECT_EQ(partner.value().roles.convention, "cmu-bvh");
  EXPECT_NEAR(partner.value().body.standing_height_m, 1.62, 0.1);
  Result<LoadedMotion> input_motion =
      load_motion({data_path("cmu-salsa/asf-amc/60.asf"), data_path("cmu-salsa/asf-amc/60_01.amc")});
  ASSERT_TRUE(input_motion);
  EXPECT_EQ(partner.value().clip.frame_count(), input_motion.value().clip.frame_count());
  std::filesystem::remove(out);
}

TEST(CliFollowRigs, FootHoldIsSwitchedOnAndSaid) {
  // --foot-hold (docs/partner.md, "Feet through a jump"): the partner is written and the summary
  // names it; without the flag it is off.
  const std::filesystem::path out = temp_file("foothold.bvh");
  const std::string input = data_path("cmu-salsa/bvh/60/60_03_scaled.bvh");
  const testing::CommandResult on = run_duet("follow" + two_pairs() + " --input " + input +
                                             " --input-fps 60 --foot-hold -o " + out.string());
  ASSERT_EQ(on.exit_code, 0) << on.output;
  EXPECT_NE(on.output.find("corrections: align,contact,smooth,footlock,blend, foot hold"),
            std::string::npos)
      << on.output;
  EXPECT_TRUE(std::filesystem::exists(out));
  const testing::CommandResult off =
      run_duet("follow" + two_pairs() + " --input " + input + " --input-fps 60 -o " + out.string());
  ASSERT_EQ(off.exit_code, 0) << off.output;
  EXPECT_EQ(off.output.find("foot hold"), std::string::npos) << off.output;
  std::filesystem::remove(out);
}

TEST(CliFollowRigs, MostlyLostInputExitsThreeWithCausesUnlessAllowed) {
  // A walk on a third-party rig: no part of the salsa.
  const std::string walk = data_path("bandai/dataset-1_walk_normal_001.bvh");
  const testing::CommandResult lost = run_duet("follow" + two_pairs() + " --input " + walk);
  EXPECT_EQ(lost.exit_code, 3) << lost.output;
  EXPECT_NE(lost.output.find("frames are lost"), std::string::npos) << lost.output;
  EXPECT_NE(lost.output.find("Likely causes"), std::string::npos) << lost.output;
  EXPECT_NE(lost.output.find("rig: the body roles"), std::string::npos) << lost.output;
  const testing::CommandResult allowed =
      run_duet("follow" + two_pairs() + " --input " + walk + " --allow-lost");
  EXPECT_EQ(allowed.exit_code, 0) << allowed.output;
}

TEST(CliFollowRigs, DancingThePartnersPartIsNamedAsTheLikelyCause) {
  // The follower's file given as the user's while the library expects the leader.
  const testing::CommandResult r =
      run_duet("follow" + two_pairs() + " --input " +
               data_path("cmu-salsa/bvh/61/61_03_scaled.bvh") + " --input-fps 60");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("--role partner"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace duet
