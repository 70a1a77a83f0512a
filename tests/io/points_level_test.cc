// A three-point recording from a camera-based tracker pitched down is levelled on loading from
// its head's path (head_path_levelling), on real motion: salsa take 01's leader, whose head dips
// by half a metre for a second at one end of the room.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "duet/io/motion_file.h"
#include "duet/io/points_csv.h"
#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"
#include "duet/motion/up_axis.h"

namespace duet {
namespace {

namespace fs = std::filesystem;

// Take 01's leader as a headset and two controllers would report them (at the joints), 60 Hz.
Clip take_01_points() {
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  Result<LoadedMotion> body =
      load_motion({std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/60/60_01_scaled.bvh"}, options);
  EXPECT_TRUE(body.ok()) << (body.ok() ? "" : body.error().message);
  Result<Clip> points = head_hands_clip(body.value().clip, body.value().roles);
  EXPECT_TRUE(points.ok()) << (points.ok() ? "" : points.error().message);
  return std::move(points).value();
}

std::vector<Vec3> heads(const Clip& points) {
  std::vector<Vec3> out;
  std::vector<Vec3> positions(static_cast<std::size_t>(points.joint_count()));
  std::vector<Quat> rotations(positions.size());
  for (int f = 0; f < points.frame_count(); ++f) {
    forward_kinematics(points.skeleton(), points.translations_ls(f), points.rotations_ls(f),
                       positions, rotations);
    out.push_back(positions[kPointsHead]);
  }
  return out;
}

class PointsLevel : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("duet_points_level_test_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `points` written as a three-point CSV and loaded as `duet follow --input` loads it.
  LoadedMotion written_and_loaded(const Clip& points, const std::string& name,
                                  const MotionLoadOptions& options = {}) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << format_points_csv(points);
    Result<LoadedMotion> loaded = load_motion({path}, options);
    EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.error().message);
    return std::move(loaded).value();
  }

  fs::path dir_;
};

TEST_F(PointsLevel, ACameraPitchedDownIsLevelledFromTheHeadsPathAndALevelWorldIsLeft) {
  const Clip level = take_01_points();
  ASSERT_GT(level.duration(), 15.0);
  const std::vector<Vec3> level_heads = heads(level);

  // The level recording stays as it is, its dip notwithstanding (read as a floor's toes, which
  // set aside points above the plane, it came out 12-14 degrees tilted).
  const LoadedMotion as_is = written_and_loaded(level, "level.csv");
  EXPECT_EQ(as_is.tilt_deg(), 0.0);
  EXPECT_EQ(as_is.up_source, "the three-point format's");

  // Pitched 12 degrees about a horizontal axis: levelled about a horizontal axis (headings kept)
  // to within 2.5 degrees of the level world (the dance's own head path is not exactly level),
  // every head within 8 cm of where it was.
  const Quat tilt(Eigen::AngleAxisd(deg_to_rad(12.0), Vec3(1.0, 0.0, 2.0).normalized()));
  Clip tilted = level;
  turn_world(tilted, tilt);
  const LoadedMotion levelled = written_and_loaded(tilted, "tilted.csv");
  EXPECT_NEAR(levelled.tilt_deg(), 12.0, 1.5);
  EXPECT_NEAR(log_map(levelled.level).normalized().dot(Vec3::UnitY()), 0.0, 1e-9);
  EXPECT_NE(levelled.up_source.find("a tilted floor read from the head's path, levelled by"),
            std::string::npos)
      << levelled.up_source;
  const std::vector<Vec3> levelled_heads = heads(levelled.clip);
  ASSERT_EQ(levelled_heads.size(), level_heads.size());
  double farthest = 0.0;
  for (std::size_t f = 0; f < level_heads.size(); ++f) {
    farthest = std::max(farthest, (levelled_heads[f] - level_heads[f]).norm());
  }
  EXPECT_LT(farthest, 0.08) << "metres (left tilted, a head a metre from the origin is 20 cm off)";
  EXPECT_LT(rad_to_deg(log_map(levelled.level * tilt).norm()), 2.5);

  // An up axis given is taken as exact, as for a body.
  MotionLoadOptions given;
  given.up_axis = UpAxis::kPosY;
  const LoadedMotion exact = written_and_loaded(tilted, "given.csv", given);
  EXPECT_EQ(exact.tilt_deg(), 0.0);
  EXPECT_EQ(exact.up_source, kUpAxisGiven);
  // A Z-up recording told so is turned to Y up (a three-point CSV's --up was ignored before).
  Clip z_up = level;
  turn_world(z_up, rotation_to_y_up(UpAxis::kPosZ).conjugate());
  MotionLoadOptions told_z;
  told_z.up_axis = UpAxis::kPosZ;
  const LoadedMotion from_z = written_and_loaded(z_up, "z-up.csv", told_z);
  EXPECT_EQ(from_z.up_axis, UpAxis::kPosZ);
  const std::vector<Vec3> from_z_heads = heads(from_z.clip);
  ASSERT_EQ(from_z_heads.size(), level_heads.size());
  for (std::size_t f = 0; f < level_heads.size(); f += 97) {
    EXPECT_LT((from_z_heads[f] - level_heads[f]).norm(), 1e-4) << f;
  }
  // Under kLevelLeastSpanS the head's path is no evidence: left as it is.
  Clip short_tilted = tilted;
  short_tilted.keep_first_frames(static_cast<int>(kLevelLeastSpanS * 60.0) - 1);
  EXPECT_EQ(written_and_loaded(short_tilted, "short.csv").tilt_deg(), 0.0);
}

TEST_F(PointsLevel, AHeadThatKeepsToTheSpotIsNoEvidenceOfATilt) {
  // The head standing on one spot for 20 s, bobbing by centimetres: whatever the heights, its path
  // spreads too little to read a slope from, so nothing is levelled.
  Clip still(make_head_hands_skeleton(), 60.0, 1200);
  for (int f = 0; f < still.frame_count(); ++f) {
    const double t = f / 60.0;
    still.translations_ls(f)[kPointsHead] =
        Vec3(0.02 * std::sin(3.0 * t), 1.6 + 0.03 * std::sin(7.0 * t), 0.02 * std::cos(2.0 * t));
    still.translations_ls(f)[kPointsLeftHand] = Vec3(-0.2, 1.0, -0.2);
    still.translations_ls(f)[kPointsRightHand] = Vec3(0.2, 1.0, -0.2);
  }
  EXPECT_TRUE(head_path_levelling(still, kPointsHead).vec().isZero(0.0));
  // No head joint: nothing to read.
  EXPECT_TRUE(head_path_levelling(still, -1).vec().isZero(0.0));
  EXPECT_TRUE(head_path_levelling(still, 7).vec().isZero(0.0));
}

}  // namespace
}  // namespace duet
