// Retargeting between rigs on real captures: the salsa DAZ rig, the MotionBuilder CMU rig of the
// handshake trial, the CMU ASF rig, and a proportioned rig of our own (A-pose, other lengths).
#include "duet/motion/retarget.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "duet/io/motion_file.h"
#include "duet/math/rotation.h"
#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"
#include "duet/motion/rig_variants.h"
#include "motion/role_directions.h"

namespace duet {
namespace {

using test::angle_deg;
using test::direction_errors;
using test::Stats;
using test::stats;

std::string data(const std::string& relative) {
  return std::string(DUET_DATA_DIR) + "/" + relative;
}

LoadedMotion load(const std::vector<std::string>& paths) {
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  Result<LoadedMotion> loaded = load_motion(paths, options);
  EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.error().message);
  return std::move(loaded.value());
}

const LoadedMotion& salsa() {
  static const LoadedMotion motion = load({data("cmu-salsa/bvh/60/60_01_scaled.bvh")});
  return motion;
}
const LoadedMotion& handshake() {
  static const LoadedMotion motion = load({data("cmu-handshake/18_01.bvh")});
  return motion;
}
const LoadedMotion& asf() {
  static const LoadedMotion motion =
      load({data("cmu-salsa/asf-amc/60.asf"), data("cmu-salsa/asf-amc/60_01.amc")});
  return motion;
}

double lowest_foot(std::span<const Vec3> p, const JointRoles& r) {
  double low = 1e9;
  for (Role foot : {Role::kLeftAnkle, Role::kLeftToe, Role::kRightAnkle, Role::kRightToe}) {
    low = std::min(low, p[static_cast<std::size_t>(r[foot])].y());
  }
  return low;
}

Clip retarget_or_fail(const Clip& source, const JointRoles& source_roles,
                      std::shared_ptr<const Skeleton> target, const JointRoles& target_roles) {
  Result<Clip> out = retarget_clip(source, source_roles, std::move(target), target_roles);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return std::move(out.value());
}

void expect_directions(const char* what, const std::vector<double>& errors, double limit_deg) {
  const Stats s = stats(errors);
  std::printf("%s: role directions max %.3g deg, median %.3g deg over %zu frames\n", what, s.max,
              s.median, errors.size());
  EXPECT_LT(s.max, limit_deg) << what;
}

TEST(Retarget, RoundTripThroughTheHandshakeRigKeepsTheRoleDirections) {
  const LoadedMotion& src = salsa();
  const Clip there =
      retarget_or_fail(src.clip, src.roles, handshake().clip.skeleton_ptr(), handshake().roles);
  const Clip back = retarget_or_fail(there, handshake().roles, src.clip.skeleton_ptr(), src.roles);
  ASSERT_EQ(back.frame_count(), src.clip.frame_count());
  expect_directions("salsa -> handshake rig",
                    direction_errors(src.clip, src.roles, there, handshake().roles, false), 2.0);
  expect_directions("salsa -> handshake rig -> salsa",
                    direction_errors(src.clip, src.roles, back, src.roles, true), 2.0);
}

TEST(Retarget, OntoTheAsfRigKeepsTheRoleDirections) {
  const LoadedMotion& src = salsa();
  const Clip out = retarget_or_fail(src.clip, src.roles, asf().clip.skeleton_ptr(), asf().roles);
  expect_directions("salsa -> ASF rig",
                    direction_errors(src.clip, src.roles, out, asf().roles, false), 2.0);
  // Pelvis -> head is a sum of trunk bones whose lengths differ between the rigs: reported only.
  const Stats trunk = stats(direction_errors(src.clip, src.roles, out, asf().roles, true));
  std::printf("salsa -> ASF rig, with pelvis -> head: max %.3f deg, median %.3f deg\n", trunk.max,
              trunk.median);
}

TEST(Retarget, ToAndFromTheBandaiRig) {
  // A third-party rig in centimetres whose roles are found from its joint names.
  const LoadedMotion bandai = load({data("bandai/dataset-1_dance-short_normal_001.bvh")});
  const LoadedMotion& src = salsa();
  const Clip there =
      retarget_or_fail(src.clip, src.roles, bandai.clip.skeleton_ptr(), bandai.roles);
  expect_directions("salsa -> Bandai rig",
                    direction_errors(src.clip, src.roles, there, bandai.roles, false), 2.0);
  const Clip back = retarget_or_fail(there, bandai.roles, src.clip.skeleton_ptr(), src.roles);
  expect_directions("salsa -> Bandai rig -> salsa",
                    direction_errors(src.clip, src.roles, back, src.roles, true), 2.0);
  const Clip dance =
      retarget_or_fail(bandai.clip, bandai.roles, src.clip.skeleton_ptr(), src.roles);
  expect_directions("Bandai dance -> salsa rig",
                    direction_errors(bandai.clip, bandai.roles, dance, src.roles, false), 2.0);
}

TEST(Retarget, TheBandaiRigsClaviclesKeepTheShoulderLine) {
  // The Bandai rig's rest pose has every bone along one axis: a copied clavicle rotation tilted
  // its shoulder line (right -> left upper arm joint) by 47 degrees on every frame. Turned
  // like bones, the clavicles put the shoulders where the source's are.
  const LoadedMotion& src = salsa();
  const LoadedMotion bandai = load({data("bandai/dataset-1_dance-short_normal_001.bvh")});
  const Clip there =
      retarget_or_fail(src.clip, src.roles, bandai.clip.skeleton_ptr(), bandai.roles);
  const std::vector<Vec3> pa = world_positions(src.clip), pb = world_positions(there);
  const auto na = static_cast<std::size_t>(src.clip.joint_count()),
             nb = static_cast<std::size_t>(there.joint_count());
  std::vector<double> errors;
  for (int f = 0; f < there.frame_count(); ++f) {
    auto line = [f](const std::vector<Vec3>& p, std::size_t n, const JointRoles& r) {
      const std::size_t base = static_cast<std::size_t>(f) * n;
      return Vec3(p[base + static_cast<std::size_t>(r[Role::kLeftShoulder])] -
                  p[base + static_cast<std::size_t>(r[Role::kRightShoulder])]);
    };
    errors.push_back(angle_deg(line(pa, na, src.roles), line(pb, nb, bandai.roles)));
  }
  const Stats s = stats(errors);
  std::printf("shoulder line on the Bandai rig: median %.2f deg, max %.2f deg\n", s.median, s.max);
  EXPECT_LT(s.median, 3.0);
}

// Median over the frames of the head's heading against the pelvis's, in degrees, with the head
// turned by `head_correction` (the rig's: where its head faces).
double median_head_off_pelvis_deg(const Clip& clip, const JointRoles& roles,
                                  const Quat& head_correction) {
  std::vector<Vec3> positions(static_cast<std::size_t>(clip.joint_count()));
  std::vector<Quat> world(positions.size());
  std::vector<double> off;
  for (int f = 0; f < clip.frame_count(); ++f) {
    forward_kinematics(clip.skeleton(), clip.translations_ls(f), clip.rotations_ls(f), positions,
                       world);
    const Quat head = world[static_cast<std::size_t>(roles[Role::kHead])] * head_correction;
    off.push_back(rad_to_deg(
        std::remainder(heading_yaw(head) - body_heading_yaw(positions, roles), 2.0 * kPi)));
  }
  return stats(off).median;
}

TEST(Retarget, TheHeadFacesAsTheSourcesOnARigWhoseRestPoseIsNoBody) {
  // The Bandai rig's rest pose says nothing of where its head faces: through the neck's rest
  // alignment, take 01 on it held its head 98 degrees off where the Bandai clips hold theirs, and
  // the Bandai walk on the salsa rig 95 degrees off. Each rig's head correction (the rest pose's,
  // or for the Bandai rig its own motion's) turns the head to face as the source's does.
  const LoadedMotion& src = salsa();
  const LoadedMotion bandai = load({data("bandai/dataset-1_walk_normal_001.bvh")});
  Result<Quat> salsa_head = head_correction(src.clip, src.roles);
  Result<Quat> bandai_head = head_correction(bandai.clip, bandai.roles);
  ASSERT_TRUE(salsa_head && bandai_head);

  RetargetOptions there_options;
  set_head_corrections(there_options, src.clip, src.roles, bandai.clip, bandai.roles);
  ASSERT_TRUE(there_options.source_head_correction && there_options.target_head_correction);
  Result<Clip> there =
      retarget_clip(src.clip, src.roles, bandai.clip.skeleton_ptr(), bandai.roles, there_options);
  ASSERT_TRUE(there) << there.error().message;
  const double take = median_head_off_pelvis_deg(src.clip, src.roles, salsa_head.value());
  const double on_bandai =
      median_head_off_pelvis_deg(there.value(), bandai.roles, bandai_head.value());
  expect_directions("salsa -> Bandai rig, head correction",
                    direction_errors(src.clip, src.roles, there.value(), bandai.roles, false), 2.0);

  RetargetOptions back_options;
  set_head_corrections(back_options, bandai.clip, bandai.roles, src.clip, src.roles);
  Result<Clip> walk =
      retarget_clip(bandai.clip, bandai.roles, src.clip.skeleton_ptr(), src.roles, back_options);
  ASSERT_TRUE(walk) << walk.error().message;
  const double walk_on_salsa =
      median_head_off_pelvis_deg(walk.value(), src.roles, salsa_head.value());
  std::printf(
      "head off the pelvis, median: take 01 %.1f, on the Bandai rig %.1f; the Bandai "
      "walk on the salsa rig %.1f degrees\n",
      take, on_bandai, walk_on_salsa);
  EXPECT_NEAR(on_bandai, take, 3.0);
  EXPECT_LT(std::abs(walk_on_salsa), 5.0);

  // Two rigs whose rest poses stand keep the rest alignment (exact both ways).
  RetargetOptions standing;
  set_head_corrections(standing, src.clip, src.roles, asf().clip, asf().roles);
  EXPECT_FALSE(standing.source_head_correction || standing.target_head_correction);
}

TEST(Retarget, OntoAProportionedRigKeepsDirectionsFeetAndScaledStrides) {
  const LoadedMotion& src = salsa();
  const RigProportions proportions = RigProportions::evaluation_variant();
  auto rig = std::make_shared<const Skeleton>(
      make_proportioned_rig(src.clip.skeleton(), src.roles, proportions));
  ASSERT_EQ(rig->validate(), "");
  // The rig really is another one: its rest upper arm points elsewhere, its legs are shorter.
  const BodyDimensions body = measure_body(*rig, src.roles);
  const BodyDimensions original = measure_body(src.clip.skeleton(), src.roles);
  EXPECT_NEAR(body.leg_length_m / original.leg_length_m, 0.92, 1e-9);
  EXPECT_NEAR(body.arm_length_m / original.arm_length_m, 1.1, 1e-9);

  const Clip out = retarget_or_fail(src.clip, src.roles, rig, src.roles);
  expect_directions("salsa -> proportioned rig",
                    direction_errors(src.clip, src.roles, out, src.roles, true), 2.0);

  // Copying the local rotations instead would not follow the rig: the check can fail.
  Clip copied(rig, src.clip.frame_rate(), src.clip.frame_count());
  for (int f = 0; f < src.clip.frame_count(); ++f) {
    std::copy_n(src.clip.rotations_ls(f).begin(), src.clip.joint_count(),
                copied.rotations_ls(f).begin());
    copied.translations_ls(f)[0] = src.clip.translations_ls(f)[0];
  }
  const Stats copy = stats(direction_errors(src.clip, src.roles, copied, src.roles, false));
  std::printf(
      "copying local rotations onto the proportioned rig instead: max %.1f deg, median "
      "%.1f deg\n",
      copy.max, copy.median);
  EXPECT_GT(copy.max, 20.0);

  const double k = body.leg_length_m / original.leg_length_m;
  const std::vector<Vec3> ps = world_positions(src.clip), pt = world_positions(out);
  const auto n = static_cast<std::size_t>(src.clip.joint_count());
  auto frame = [n](const std::vector<Vec3>& p, int f) {
    return std::span<const Vec3>(p.data() + static_cast<std::size_t>(f) * n, n);
  };
  double worst_foot = 0.0, worst_path = 0.0, worst_step = 0.0, previous_lift = 0.0;
  const Vec3 start_s = pelvis_centre(frame(ps, 0), src.roles),
             start_t = pelvis_centre(frame(pt, 0), src.roles);
  for (int f = 0; f < src.clip.frame_count(); ++f) {
    worst_foot = std::max(worst_foot, std::abs(lowest_foot(frame(pt, f), src.roles) -
                                               k * lowest_foot(frame(ps, f), src.roles)));
    Vec3 moved_s = pelvis_centre(frame(ps, f), src.roles) - start_s;
    Vec3 moved_t = pelvis_centre(frame(pt, f), src.roles) - start_t;
    moved_s.y() = moved_t.y() = 0.0;
    worst_path = std::max(worst_path, (moved_t - k * moved_s).norm());
    // Smoothness: the pelvis height minus the scaled source's changes little from frame to frame.
    const double lift =
        pelvis_centre(frame(pt, f), src.roles).y() - k * pelvis_centre(frame(ps, f), src.roles).y();
    if (f > 0) worst_step = std::max(worst_step, std::abs(lift - previous_lift));
    previous_lift = lift;
  }
  // Foot skate: while a source toe is planted (low and still), how far the target's toe slides.
  // (The salsa toe End Sites sit 4-5 cm up when the foot is flat.)
  double slide_sum = 0.0, slide_max = 0.0;
  int planted = 0;
  for (int f = 1; f < src.clip.frame_count(); ++f) {
    for (Role toe : {Role::kLeftToe, Role::kRightToe}) {
      const auto j = static_cast<std::size_t>(src.roles[toe]);
      Vec3 step_s = frame(ps, f)[j] - frame(ps, f - 1)[j];
      Vec3 step_t = frame(pt, f)[j] - frame(pt, f - 1)[j];
      step_s.y() = step_t.y() = 0.0;
      if (frame(ps, f)[j].y() > 0.06 || step_s.norm() > 0.001) continue;
      slide_sum += step_t.norm();
      slide_max = std::max(slide_max, step_t.norm());
      ++planted;
    }
  }
  std::printf(
      "proportioned rig: planted toes (%d toe-frames) slide %.2f mm per frame on average, "
      "at most %.2f mm\n",
      planted, 1000.0 * slide_sum / std::max(planted, 1), 1000.0 * slide_max);
  EXPECT_GT(planted, 100);
  EXPECT_LT(slide_sum / planted, 0.002);
  std::printf(
      "proportioned rig: lowest foot off by at most %.2g m; pelvis floor path off by at "
      "most %.2g m; height correction changes by at most %.2f mm per frame\n",
      worst_foot, worst_path, 1000.0 * worst_step);
  EXPECT_LT(worst_foot, 0.02);
  EXPECT_LT(worst_path, 1e-6);
  EXPECT_LT(worst_step, 0.01);
}

TEST(Retarget, SameRigIsTheIdentityOnTheRoleJoints) {
  const LoadedMotion& src = salsa();
  const Clip out = retarget_or_fail(src.clip, src.roles, src.clip.skeleton_ptr(), src.roles);
  const std::vector<Vec3> ps = world_positions(src.clip), pt = world_positions(out);
  const auto n = static_cast<std::size_t>(src.clip.joint_count());
  double worst = 0.0;
  for (int f = 0; f < src.clip.frame_count(); ++f) {
    for (int joint : src.roles.joints) {
      const std::size_t i = static_cast<std::size_t>(f) * n + static_cast<std::size_t>(joint);
      worst = std::max(worst, (pt[i] - ps[i]).norm());
    }
  }
  std::printf("same rig: role joints moved by at most %.3g m\n", worst);
  EXPECT_LT(worst, 1e-6);
}

TEST(Retarget, FramesAreFiniteAndBadRolesAreNamed) {
  const LoadedMotion& src = salsa();
  const Clip out =
      retarget_or_fail(src.clip, src.roles, handshake().clip.skeleton_ptr(), handshake().roles);
  for (int f = 0; f < out.frame_count(); ++f) {
    for (const Quat& q : out.rotations_ls(f)) ASSERT_TRUE(q.coeffs().allFinite()) << f;
    for (const Vec3& t : out.translations_ls(f)) ASSERT_TRUE(t.allFinite()) << f;
  }
  JointRoles broken = handshake().roles;
  broken.joints[static_cast<std::size_t>(Role::kLeftKnee)] = 999;
  Result<Clip> bad = retarget_clip(src.clip, src.roles, handshake().clip.skeleton_ptr(), broken, {},
                                   "salsa.bvh", "rig.bvh");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("rig.bvh"), std::string::npos) << bad.error().message;
  EXPECT_NE(bad.error().message.find("left_knee"), std::string::npos) << bad.error().message;
  // Legs of no length: strides cannot be scaled.
  JointRoles flat = handshake().roles;
  for (Role r :
       {Role::kLeftKnee, Role::kLeftAnkle, Role::kRightHip, Role::kRightKnee, Role::kRightAnkle}) {
    flat.joints[static_cast<std::size_t>(r)] = flat[Role::kLeftHip];
  }
  bad = retarget_clip(src.clip, src.roles, handshake().clip.skeleton_ptr(), flat, {}, "salsa.bvh",
                      "rig.bvh");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("rig.bvh: the legs have no length"), std::string::npos)
      << bad.error().message;
}

TEST(RigProportions, ParsesKeysAndRejectsNonsense) {
  RigProportions p;
  std::string error;
  ASSERT_TRUE(parse_rig_proportions("arms=1.1,legs=0.92,trunk=1.05,arms_down=40", p, error))
      << error;
  EXPECT_DOUBLE_EQ(p.arms, 1.1);
  EXPECT_DOUBLE_EQ(p.legs, 0.92);
  EXPECT_DOUBLE_EQ(p.trunk, 1.05);
  EXPECT_DOUBLE_EQ(p.arms_down_deg, 40.0);
  EXPECT_FALSE(parse_rig_proportions("arms=-1", p, error));
  EXPECT_NE(error.find("arms=-1"), std::string::npos) << error;
  EXPECT_FALSE(parse_rig_proportions("wings=2", p, error));
  EXPECT_NE(error.find("unknown key"), std::string::npos) << error;
  EXPECT_FALSE(parse_rig_proportions("legs", p, error));
  EXPECT_FALSE(parse_rig_proportions("legs=abc", p, error));
  EXPECT_DOUBLE_EQ(p.arms, 1.1);  // a failed parse changes nothing
}

}  // namespace
}  // namespace duet
