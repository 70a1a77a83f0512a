// End-to-end tests of `duet retarget` on the real CMU files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "apps/run_command.h"
#include "duet/io/motion_file.h"
#include "duet/motion/forward_kinematics.h"

namespace duet::testing {
namespace {

const std::string kSalsa = data_path("cmu-salsa/bvh/60/60_01_scaled.bvh");
const std::string kHandshake = data_path("cmu-handshake/18_01.bvh");

std::filesystem::path temp(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("duet_cli_retarget_" + name);
}

LoadedMotion load(const std::vector<std::string>& paths) {
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  Result<LoadedMotion> loaded = load_motion(paths, options);
  EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.error().message);
  return std::move(loaded.value());
}

// Per frame, the height of the lowest ankle or toe.
std::vector<double> lowest_feet(const LoadedMotion& m) {
  const std::vector<Vec3> p = world_positions(m.clip);
  const auto n = static_cast<std::size_t>(m.clip.joint_count());
  std::vector<double> lows;
  for (int f = 0; f < m.clip.frame_count(); ++f) {
    double low = 1e9;
    for (Role r : {Role::kLeftAnkle, Role::kLeftToe, Role::kRightAnkle, Role::kRightToe}) {
      low = std::min(low,
                     p[static_cast<std::size_t>(f) * n + static_cast<std::size_t>(m.roles[r])].y());
    }
    lows.push_back(low);
  }
  return lows;
}

TEST(CliRetarget, OntoTheHandshakeRigReadsBackAtTheRigsSizeWithFeetOnTheFloor) {
  const auto out = temp("handshake.bvh");
  const CommandResult r =
      run_duet("retarget --fps 60 " + kSalsa + " --rig " + kHandshake + " -o " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const LoadedMotion source = load({kSalsa});
  const LoadedMotion rig = load({kHandshake});
  const LoadedMotion written = load({out.string()});
  EXPECT_EQ(written.roles.convention, "cmu-bvh");
  ASSERT_EQ(written.clip.frame_count(), source.clip.frame_count());
  // Read back at true size: the rig's body, not 1/0.056 times it.
  EXPECT_NEAR(written.body.leg_length_m, rig.body.leg_length_m, 1e-4);
  EXPECT_NEAR(written.body.standing_height_m, rig.body.standing_height_m, 1e-3);
  const double k = rig.body.leg_length_m / source.body.leg_length_m;
  const std::vector<double> feet_in = lowest_feet(source), feet_out = lowest_feet(written);
  double worst = 0.0;
  for (std::size_t f = 0; f < feet_in.size(); ++f) {
    worst = std::max(worst, std::abs(feet_out[f] - k * feet_in[f]));
  }
  std::printf("CLI salsa -> handshake rig: lowest foot off by at most %.2g m (k = %.4f)\n", worst,
              k);
  EXPECT_LT(worst, 0.02);
  std::filesystem::remove(out);
}

TEST(CliRetarget, OntoARigMadeInCodeByName) {
  // The evaluation's rigs of another build (generic_rigs.h) as files of one's own: written in
  // metres, their roles found again from the joint names; a misspelt name is no file either.
  const auto out = temp("avatar.bvh");
  CommandResult r =
      run_duet("retarget --fps 60 " + kSalsa + " --rig game-avatar -o " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const LoadedMotion written = load({out.string()});
  EXPECT_EQ(written.roles.convention, "names");
  EXPECT_EQ(written.units_name, "metres");
  EXPECT_NEAR(written.body.standing_height_m, 1.80, 0.08);
  EXPECT_EQ(written.clip.frame_count(), load({kSalsa}).clip.frame_count());
  std::filesystem::remove(out);
  r = run_duet("retarget --fps 60 " + kSalsa + " --rig game-avatr -o " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("nor a rig made in code: game-avatar"), std::string::npos) << r.output;
  r = run_duet("retarget --fps 60 " + kSalsa + " --rig depth-camera --rig-scale 0.01 -o " +
               out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--rig-scale and --rig-map do not apply"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliRetarget, ProportionsWithoutARigUseTheInputsOwnSkeleton) {
  const auto out = temp("proportioned.bvh");
  const CommandResult r =
      run_duet("retarget --fps 60 " + kSalsa +
               " --proportions arms=1.1,legs=0.92,trunk=1.05,arms_down=40 -o " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const LoadedMotion source = load({kSalsa});
  const LoadedMotion written = load({out.string()});
  EXPECT_EQ(written.roles.convention, "daz");
  EXPECT_NEAR(written.body.leg_length_m / source.body.leg_length_m, 0.92, 1e-4);
  EXPECT_NEAR(written.body.arm_length_m / source.body.arm_length_m, 1.1, 1e-4);
  std::filesystem::remove(out);
}

TEST(CliRetarget, TakesTheAsfRigAsOneWordLikeEveryOtherMotionOption) {
  const std::string asf_word =
      data_path("cmu-salsa/asf-amc/60.asf") + "+" + data_path("cmu-salsa/asf-amc/60_01.amc");
  const auto out = temp("asf_word.bvh");
  const CommandResult r =
      run_duet("retarget --fps 60 " + kSalsa + " --rig " + asf_word + " -o " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const LoadedMotion written = load({out.string()});
  EXPECT_EQ(written.roles.convention, "cmu-asf");
  EXPECT_NEAR(written.body.standing_height_m, 1.71, 0.05);
  // A word whose AMC is missing is a usage error naming the missing part.
  const CommandResult bad = run_duet("retarget " + data_path("cmu-salsa/asf-amc/60.asf") +
                                     "+missing.amc --rig " + kHandshake + " -o " + out.string());
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("missing.amc"), std::string::npos) << bad.output;
  std::filesystem::remove(out);
}

TEST(CliRetarget, BadInputFailsWithReasonAndWritesNothing) {
  const auto out = temp("bad.bvh");
  std::filesystem::remove(out);
  CommandResult r =
      run_duet("retarget " + kSalsa + " --rig /nonexistent/rig.bvh -o " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/rig.bvh"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));

  // A rig whose roles cannot be found: a three-joint chain.
  const auto no_roles = temp("no_roles.bvh");
  {
    std::FILE* f = std::fopen(no_roles.c_str(), "w");
    std::fputs(
        "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition "
        "Zrotation Xrotation Yrotation\n JOINT b\n {\n  OFFSET 0 1 0\n  CHANNELS 3 "
        "Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 0 1 0\n  }\n }\n}\n"
        "MOTION\nFrames: 1\nFrame Time: 0.0333\n0 0 0 0 0 0 0 0 0\n",
        f);
    std::fclose(f);
  }
  r = run_duet("retarget " + kSalsa + " --rig " + no_roles.string() + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(no_roles.string()), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove(no_roles);

  r = run_duet("retarget " + kSalsa + " --proportions arms=0 -o " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("arms=0"), std::string::npos) << r.output;
  r = run_duet("retarget " + kSalsa + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--rig"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace duet::testing
