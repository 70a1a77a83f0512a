#include "duet/motion/up_axis.h"

#include <gtest/gtest.h>

#include <cmath>

#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"
#include "features/synthetic_dancer.h"

namespace duet {
namespace {

using testing::daz_roles;
using testing::make_dance;
using testing::make_role_skeleton;

constexpr UpAxis kAllAxes[] = {UpAxis::kPosY, UpAxis::kNegY, UpAxis::kPosZ,
                               UpAxis::kNegZ, UpAxis::kPosX, UpAxis::kNegX};

TEST(UpAxis, NamesParseAndEachRotationTakesItsAxisToY) {
  for (const UpAxis axis : kAllAxes) {
    UpAxis parsed = UpAxis::kPosY;
    ASSERT_TRUE(parse_up_axis(up_axis_name(axis), parsed)) << up_axis_name(axis);
    EXPECT_EQ(parsed, axis);
    EXPECT_LT((rotation_to_y_up(axis) * up_axis_vector(axis) - Vec3::UnitY()).norm(), 1e-12)
        << up_axis_name(axis);
  }
  UpAxis axis = UpAxis::kPosY;
  EXPECT_TRUE(parse_up_axis("z", axis));
  EXPECT_EQ(axis, UpAxis::kPosZ);
  EXPECT_TRUE(parse_up_axis("-x", axis));
  EXPECT_EQ(axis, UpAxis::kNegX);
  EXPECT_FALSE(parse_up_axis("", axis));
  EXPECT_FALSE(parse_up_axis("up", axis));
  EXPECT_FALSE(parse_up_axis("+w", axis));
}

TEST(UpAxis, IsReadFromTheBodyInEveryWorldAndTurnedBackExactly) {
  auto skeleton = make_role_skeleton();
  const JointRoles roles = daz_roles(*skeleton);
  const Clip dance = make_dance(skeleton, 60.0, 300);
  const UpAxisDetection y_up = detect_up_axis(dance, roles);
  EXPECT_TRUE(y_up.problem.empty()) << y_up.problem;
  EXPECT_EQ(y_up.axis, UpAxis::kPosY);
  EXPECT_LT(y_up.off_axis_deg, 25.0);  // the synthetic dancer swings its root and spine a lot
  for (const UpAxis axis : kAllAxes) {
    // The same dance in a world whose up is `axis`.
    Clip other = dance;
    turn_world(other, rotation_to_y_up(axis).conjugate());
    const UpAxisDetection read = detect_up_axis(other, roles);
    EXPECT_TRUE(read.problem.empty()) << up_axis_name(axis) << ": " << read.problem;
    EXPECT_EQ(read.axis, axis) << up_axis_name(axis);
    EXPECT_NEAR(read.off_axis_deg, y_up.off_axis_deg, 1e-6);
    // Turned back to Y-up, every joint is where it was.
    turn_world(other, rotation_to_y_up(read.axis));
    const std::vector<Vec3> a = world_positions(dance);
    const std::vector<Vec3> b = world_positions(other);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_LT((a[i] - b[i]).norm(), 1e-9) << up_axis_name(axis) << " value " << i;
    }
  }
}

TEST(UpAxis, SaysWhenTheBodyCannotTell) {
  auto skeleton = make_role_skeleton();
  const JointRoles roles = daz_roles(*skeleton);
  // A body standing in its rest pose, leaning 45 degrees between two axes on every frame.
  Clip leaning(skeleton, 60.0, 120);
  // Upright: the head above the middle of the feet, but for the toes' reach forwards.
  EXPECT_LT(detect_up_axis(leaning, roles).off_axis_deg, 5.0);
  turn_world(leaning, Quat(Eigen::AngleAxisd(deg_to_rad(45.0), Vec3::UnitX())));
  const UpAxisDetection read = detect_up_axis(leaning, roles);
  EXPECT_FALSE(read.problem.empty());
  EXPECT_NE(read.problem.find("degrees from the nearest axis"), std::string::npos) << read.problem;
  // No frames, no roles.
  EXPECT_FALSE(detect_up_axis(Clip(skeleton, 60.0, 0), roles).problem.empty());
  JointRoles no_head = roles;
  no_head.joints[static_cast<int>(Role::kHead)] = -1;
  EXPECT_FALSE(detect_up_axis(leaning, no_head).problem.empty());
  // Half the clip upside down: the feet-to-head directions cancel out.
  Clip flipping = make_dance(skeleton, 60.0, 120);
  const Quat flip(Eigen::AngleAxisd(kPi, Vec3::UnitX()));
  for (int f = 0; f < flipping.frame_count(); f += 2) {
    flipping.rotations_ls(f)[0] = flip * flipping.rotations_ls(f)[0];
    flipping.translations_ls(f)[0] = flip * flipping.translations_ls(f)[0];
  }
  const UpAxisDetection flipped = detect_up_axis(flipping, roles);
  EXPECT_NE(flipped.problem.find("no consistent way"), std::string::npos) << flipped.problem;
}

TEST(UpAxis, ATiltedFloorIsLevelledAboutAHorizontalAxisAndASmallLeanIsLeftAlone) {
  // A body standing in its rest pose on a floor tilted 12 degrees about a horizontal axis.
  auto skeleton = make_role_skeleton();
  const JointRoles roles = daz_roles(*skeleton);
  Clip standing(skeleton, 60.0, 360);
  const Vec3 upright = detect_up_axis(standing, roles).mean_up;
  const Quat tilt(Eigen::AngleAxisd(deg_to_rad(12.0), Vec3(1.0, 0.0, 2.0).normalized()));
  turn_world(standing, tilt);
  const UpAxisDetection read = detect_up_axis(standing, roles);
  ASSERT_TRUE(read.problem.empty()) << read.problem;
  EXPECT_EQ(read.axis, UpAxis::kPosY);
  EXPECT_LT((read.mean_up - tilt * upright).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(read.span_s, 6.0);
  const Quat level = levelling_rotation(read);
  EXPECT_NEAR(rad_to_deg(log_map(level).norm()), tilt_from_vertical_deg(read.mean_up), 1e-9);
  EXPECT_NEAR(log_map(level).normalized().dot(Vec3::UnitY()), 0.0, 1e-12);  // headings kept
  turn_world(standing, level);
  EXPECT_NEAR(tilt_from_vertical_deg(detect_up_axis(standing, roles).mean_up), 0.0, 1e-9);
  // Under kLevelLeastSpanS of motion the mean is no evidence of a tilt: nothing is turned.
  Clip short_clip(skeleton, 60.0, 240);
  turn_world(short_clip, tilt);
  EXPECT_TRUE(levelling_rotation(detect_up_axis(short_clip, roles)).vec().isZero(0.0));

  // A lean under kLevelFromDeg is the dancer's own: nothing is turned. Nor for no direction.
  const Vec3 leaning = Quat(Eigen::AngleAxisd(deg_to_rad(2.0), Vec3::UnitZ())) * Vec3::UnitY();
  EXPECT_TRUE(levelling_rotation(leaning).vec().isZero(0.0));
  EXPECT_TRUE(levelling_rotation(Vec3::Zero()).vec().isZero(0.0));
  EXPECT_TRUE(levelling_rotation(Vec3(std::nan(""), 1.0, 0.0)).vec().isZero(0.0));

  // A Y-up clip turned into a file's world (an up axis and a tilt) and back is what it was.
  const Clip dance = make_dance(skeleton, 60.0, 120);
  const Quat file_to_y_up = level * rotation_to_y_up(UpAxis::kPosZ);
  Clip in_file = dance;
  turn_world(in_file, file_to_y_up);
  turn_to_file_world(in_file, file_to_y_up);
  const std::vector<Vec3> a = world_positions(dance);
  const std::vector<Vec3> b = world_positions(in_file);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_LT((a[i] - b[i]).norm(), 1e-9) << i;
}

}  // namespace
}  // namespace duet
