// load_motion's roles and units on real files: the Bandai rig (no built-in map, centimetres)
// loads with roles from its joint names and units guessed from its height; the CMU files keep
// their conventions and units; --scale overrides; an unknown rig loads only for inspection.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "duet/io/motion_file.h"

namespace duet {
namespace {

const std::string kData = DUET_DATA_DIR;

std::string joint_of(const LoadedMotion& m, Role role) {
  return m.clip.skeleton().joints[static_cast<std::size_t>(m.roles[role])].name;
}

TEST(MotionUnits, BandaiClipsLoadWithoutAMapInCentimetres) {
  for (const char* clip : {"dance-short", "walk", "byebye"}) {
    const std::string path = kData + "/bandai/dataset-1_" + clip + "_normal_001.bvh";
    Result<LoadedMotion> m = load_motion({path});
    ASSERT_TRUE(m) << m.error().message;
    const LoadedMotion& motion = m.value();
    EXPECT_EQ(motion.roles.convention, "names") << path;
    EXPECT_EQ(motion.units_source, "guessed from height");
    EXPECT_EQ(motion.units_name, "centimetres");
    EXPECT_DOUBLE_EQ(motion.metres_per_unit, 0.01);
    EXPECT_EQ(motion.units_warning, "");
    // 1.52 m with kHeightPerChainLength 1.17 (the head joint sits low on this rig).
    EXPECT_GT(motion.body.standing_height_m, 1.4) << path;
    EXPECT_LT(motion.body.standing_height_m, 1.9) << path;
    EXPECT_NEAR(motion.body.leg_length_m, 0.80, 0.01);
    EXPECT_EQ(joint_of(motion, Role::kHips), "Hips");  // not the root joint_Root
    EXPECT_EQ(joint_of(motion, Role::kChest), "Chest");
    EXPECT_EQ(joint_of(motion, Role::kLeftShoulder), "UpperArm_L");  // Shoulder_L: clavicle
    EXPECT_EQ(joint_of(motion, Role::kRightElbow), "LowerArm_R");
    EXPECT_EQ(joint_of(motion, Role::kLeftWrist), "Hand_L");
    EXPECT_EQ(joint_of(motion, Role::kRightHip), "UpperLeg_R");
    EXPECT_EQ(joint_of(motion, Role::kLeftKnee), "LowerLeg_L");
    EXPECT_EQ(joint_of(motion, Role::kRightToe), "Toes_R");
  }
}

TEST(MotionUnits, CmuFilesKeepTheirConventionsAndUnits) {
  Result<LoadedMotion> salsa = load_motion({kData + "/cmu-salsa/bvh/60/60_01_scaled.bvh"});
  ASSERT_TRUE(salsa) << salsa.error().message;
  EXPECT_EQ(salsa.value().roles.convention, "daz");
  EXPECT_EQ(salsa.value().units_source, "convention daz");
  EXPECT_DOUBLE_EQ(salsa.value().metres_per_unit, 1.0 / 0.768);
  EXPECT_EQ(joint_of(salsa.value(), Role::kLeftShoulder), "lShldr");
  EXPECT_EQ(joint_of(salsa.value(), Role::kRightToe), "rFoot_End");
  EXPECT_NEAR(salsa.value().body.standing_height_m, 1.75, 0.02);

  Result<LoadedMotion> handshake = load_motion({kData + "/cmu-handshake/19_01.bvh"});
  ASSERT_TRUE(handshake) << handshake.error().message;
  EXPECT_EQ(handshake.value().roles.convention, "cmu-bvh");
  EXPECT_EQ(handshake.value().units_source, "convention cmu-bvh");
  EXPECT_EQ(joint_of(handshake.value(), Role::kLeftShoulder), "LeftArm");
  EXPECT_NEAR(handshake.value().body.standing_height_m, 1.68, 0.02);

  Result<LoadedMotion> asf = load_motion(
      {kData + "/cmu-salsa/asf-amc/60.asf", kData + "/cmu-salsa/asf-amc/60_01.amc"});
  ASSERT_TRUE(asf) << asf.error().message;
  EXPECT_EQ(asf.value().roles.convention, "cmu-asf");
  EXPECT_EQ(asf.value().units_source, "ASF file");
  EXPECT_NEAR(asf.value().body.standing_height_m, 1.71, 0.02);
}

TEST(MotionUnits, ScaleOverridesTheGuess) {
  MotionLoadOptions options;
  options.metres_per_unit = 0.02;
  Result<LoadedMotion> m = load_motion({kData + "/bandai/dataset-1_walk_normal_001.bvh"}, options);
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_EQ(m.value().units_source, "given (--scale)");
  EXPECT_DOUBLE_EQ(m.value().metres_per_unit, 0.02);
  EXPECT_NEAR(m.value().body.standing_height_m, 3.04, 0.02);  // twice the guessed body
  EXPECT_NE(m.value().units_warning.find("not a plausible adult height"), std::string::npos);
}

TEST(MotionUnits, GuessPicksThePlausibleUnit) {
  EXPECT_EQ(guess_units_from_height(1.75).name, "metres");
  EXPECT_EQ(guess_units_from_height(152.0).name, "centimetres");  // not a 152 m giant
  EXPECT_EQ(guess_units_from_height(1800.0).name, "millimetres");
  EXPECT_EQ(guess_units_from_height(68.0).name, "inches");
  EXPECT_EQ(guess_units_from_height(30.0).name, "CMU units");
  const UnitGuess giant = guess_units_from_height(500.0);  // 500, 5, 0.5, 12.7 or 28 m
  EXPECT_EQ(giant.name, "metres");
  EXPECT_NE(giant.warning.find("implausible"), std::string::npos) << giant.warning;
  EXPECT_NE(guess_units_from_height(0.0).warning, "");
}

// A BVH states no units, so a writer must pick the ones the reader will infer (issue 14: a
// converted ASF read back 10 cm tall, a converted salsa take 1.3x too big).
TEST(MotionUnits, ReadableUnitsAreTheOnesTheReaderInfers) {
  Result<LoadedMotion> salsa = load_motion({kData + "/cmu-salsa/bvh/60/60_01_scaled.bvh"});
  Result<LoadedMotion> asf =
      load_motion({kData + "/cmu-salsa/asf-amc/60.asf", kData + "/cmu-salsa/asf-amc/60_01.amc"});
  Result<LoadedMotion> bandai = load_motion({kData + "/bandai/dataset-1_walk_normal_001.bvh"});
  ASSERT_TRUE(salsa && asf && bandai);
  const Skeleton& daz = salsa.value().clip.skeleton();
  const Skeleton& cmu = asf.value().clip.skeleton();
  const Skeleton& names = bandai.value().clip.skeleton();
  // Metres would read back in the convention's units.
  EXPECT_DOUBLE_EQ(metres_per_unit_read_back(daz, 1.0), 1.0 / 0.768);
  EXPECT_DOUBLE_EQ(metres_per_unit_read_back(cmu, 1.0), 0.0254 / 0.45);
  EXPECT_DOUBLE_EQ(readable_metres_per_unit(daz, 1.0), 1.0 / 0.768);
  EXPECT_DOUBLE_EQ(readable_metres_per_unit(cmu, asf.value().metres_per_unit), 0.0254 / 0.45);
  // A rig with no known units keeps the source's when the height guess finds them again.
  EXPECT_DOUBLE_EQ(readable_metres_per_unit(names, 0.01), 0.01);
  EXPECT_DOUBLE_EQ(readable_metres_per_unit(names, 0.001), 0.001);
  EXPECT_DOUBLE_EQ(readable_metres_per_unit(names, 1.0), 1.0);
  // Units the guess would not find (a 1.5 m body as 0.3 units of 5 m): metres.
  EXPECT_DOUBLE_EQ(readable_metres_per_unit(names, 5.0), 1.0);
}

class UnknownRigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // A chain of three joints: nothing a body could be.
    path_ = (std::filesystem::temp_directory_path() /
             ("duet_unknown_rig_" + std::to_string(::getpid()) + ".bvh"))
                .string();
    std::ofstream(path_) << "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition "
                            "Yposition Zposition\n JOINT b\n {\n  OFFSET 0 10 0\n  CHANNELS 3 "
                            "Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 0 10 0\n  "
                            "}\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.0333333\n0 0 0 0 0 0\n";
  }
  void TearDown() override { std::filesystem::remove(path_); }
  std::string path_;
};

TEST_F(UnknownRigTest, FailsWithTheMissingRolesUnlessOnlyInspected) {
  Result<LoadedMotion> strict = load_motion({path_});
  ASSERT_FALSE(strict);
  EXPECT_NE(strict.error().message.find(path_), std::string::npos);
  EXPECT_NE(strict.error().message.find("left_wrist"), std::string::npos)
      << strict.error().message;
  MotionLoadOptions inspect;
  inspect.require_roles = false;
  Result<LoadedMotion> loose = load_motion({path_}, inspect);
  ASSERT_TRUE(loose) << loose.error().message;
  EXPECT_FALSE(loose.value().role_detection.complete());
  EXPECT_EQ(loose.value().role_detection.missing_roles().size(),
            static_cast<std::size_t>(kRoleCount));
  EXPECT_EQ(loose.value().units_source, "default (metres)");
  EXPECT_NE(loose.value().units_warning, "");
  EXPECT_FALSE(loose.value().body.valid());
}

}  // namespace
}  // namespace duet
