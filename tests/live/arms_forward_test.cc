// Three points' body calibration (arms_forward.h) on real rigs: the pose measured from a body's
// skeleton agrees with the same pose held and seen as three points, and the same performance on
// another rig, calibrated, gives the library rig's hand places and is followed as well.
#include "duet/motion/arms_forward.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "duet/eval/performance.h"
#include "duet/features/feature_extractor.h"
#include "duet/follow/hmm_follower.h"
#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/head_hands.h"
#include "duet/motion/retarget.h"
#include "live/salsa_library.h"

namespace duet::test {
namespace {

LoadedMotion load(const std::vector<std::string>& files, double fps = 0.0) {
  MotionLoadOptions options;
  if (fps > 0.0) options.frame_rate = fps;
  Result<LoadedMotion> loaded = load_motion(files, options);
  EXPECT_TRUE(loaded) << loaded.error().message;
  return std::move(loaded).value();
}

LoadedMotion salsa_take(const std::string& trial) {
  return load({kSalsaData + "/cmu-salsa/bvh/60/60_" + trial + "_scaled.bvh"}, 60.0);
}

// `motion` onto the CMU ASF skeleton of subject 60, by role directions (duet retarget).
LoadedMotion on_asf_rig(const LoadedMotion& motion) {
  const LoadedMotion rig =
      load({kSalsaData + "/cmu-salsa/asf-amc/60.asf", kSalsaData + "/cmu-salsa/asf-amc/60_01.amc"});
  Result<Clip> moved = retarget_clip(motion.clip, motion.roles, rig.clip.skeleton_ptr(), rig.roles);
  EXPECT_TRUE(moved) << moved.error().message;
  LoadedMotion out = rig;
  out.clip = std::move(moved).value();
  return out;
}

// Take 60_10 on the CMU handshake rig of 18_01 (by role directions) as three points with a
// headset's noise, and that body's calibration pose and head height standing.
struct ThreePointsOnRig {
  Performance points;
  ArmsForward pose;
  double head_m = 0.0;
};
ThreePointsOnRig take_10_on_handshake_rig_as_points() {
  const LoadedMotion daz = salsa_take("10");
  const LoadedMotion rig = load({kSalsaData + "/cmu-handshake/18_01.bvh"});
  Result<Clip> moved = retarget_clip(daz.clip, daz.roles, rig.clip.skeleton_ptr(), rig.roles);
  EXPECT_TRUE(moved) << moved.error().message;
  Performance performance;
  performance.motion = std::move(moved).value();
  performance.roles = rig.roles;
  ThreePointsOnRig out;
  Result<ArmsForward> pose = arms_forward_of_body(performance.motion, performance.roles, 10);
  EXPECT_TRUE(pose);
  out.pose = pose.value();
  out.head_m = highest_head_m(performance.motion, performance.roles);
  Result<Performance> points = with_head_hands(std::move(performance), PointNoiseOptions{});
  EXPECT_TRUE(points);
  out.points = std::move(points).value();
  return out;
}

// Frame `frame` of `body` with both arms turned straight forward, as one frame: each upper arm,
// then each forearm, turned in the world so its bone points where the head faces (a user looks
// straight ahead in the pose; this dancer's head is turned 10 degrees from the pelvis).
Clip arms_held_forward(const LoadedMotion& body, int frame) {
  Clip pose(body.clip.skeleton_ptr(), body.clip.frame_rate(), 1);
  std::ranges::copy(body.clip.translations_ls(frame), pose.translations_ls(0).begin());
  std::ranges::copy(body.clip.rotations_ls(frame), pose.rotations_ls(0).begin());
  const Skeleton& skeleton = pose.skeleton();
  const auto n = static_cast<std::size_t>(skeleton.joint_count());
  std::vector<Vec3> positions(n);
  std::vector<Quat> world(n);
  forward_kinematics(skeleton, pose.translations_ls(0), pose.rotations_ls(0), positions, world);
  const auto at = [&](Role role) { return static_cast<std::size_t>(body.roles[role]); };
  const Quat head_canonical =
      world[at(Role::kHead)] * head_correction(body.clip, body.roles).value();
  const double yaw = heading_yaw(head_canonical);
  const Vec3 ahead(std::sin(yaw), 0.0, std::cos(yaw));
  for (const auto& [joint, child] : {std::pair{Role::kLeftShoulder, Role::kLeftElbow},
                                     {Role::kRightShoulder, Role::kRightElbow},
                                     {Role::kLeftElbow, Role::kLeftWrist},
                                     {Role::kRightElbow, Role::kRightWrist}}) {
    forward_kinematics(skeleton, pose.translations_ls(0), pose.rotations_ls(0), positions, world);
    const Quat turn = Quat::FromTwoVectors(positions[at(child)] - positions[at(joint)], ahead);
    const int parent = skeleton.joints[at(joint)].parent;
    const Quat parent_world =
        parent >= 0 ? world[static_cast<std::size_t>(parent)] : Quat::Identity();
    pose.rotations_ls(0)[at(joint)] =
        (parent_world.conjugate() * turn * world[at(joint)]).normalized();
  }
  return pose;
}

void expect_near(const ArmsForward& a, const ArmsForward& b, double tolerance) {
  for (std::size_t side = 0; side < 2; ++side) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(a.wrists[side][k], b.wrists[side][k], tolerance)
          << "side " << side << " axis " << k;
    }
  }
}

TEST(ArmsForward, TheSkeletonsMeasureIsThePoseHeldAsThreePoints) {
  // What the library and the evaluation compute from a rig (shoulders plus the arm's length)
  // must be what a user holding the pose shows as three points, on the library's rig and on the
  // ASF rig (other shoulders, other joint places). Frame 0: the dancer stands.
  const LoadedMotion daz = salsa_take("01");
  for (const LoadedMotion& body : {daz, on_asf_rig(daz)}) {
    LoadedMotion posed = body;
    posed.clip = arms_held_forward(body, 0);
    Result<ArmsForward> from_body = arms_forward_of_body(posed.clip, posed.roles);
    ASSERT_TRUE(from_body) << from_body.error().message;
    Result<Clip> points = head_hands_clip(posed.clip, posed.roles);
    ASSERT_TRUE(points) << points.error().message;
    Result<ArmsForward> held = arms_forward_of_points(points.value());
    ASSERT_TRUE(held) << held.error().message;
    expect_near(held.value(), from_body.value(), 0.02);
    EXPECT_GT(held.value().wrists[0].z(), 0.2);  // in front, left on the left
    EXPECT_GT(held.value().wrists[0].x(), held.value().wrists[1].x());
  }
}

TEST(ArmsForward, TheAsfRigsWiderShouldersShowInItsCalibration) {
  const LoadedMotion daz = salsa_take("01");
  Result<ArmsForward> native = arms_forward_of_body(daz.clip, daz.roles, 10);
  const LoadedMotion asf_body = on_asf_rig(daz);
  Result<ArmsForward> asf = arms_forward_of_body(asf_body.clip, asf_body.roles, 10);
  ASSERT_TRUE(native && asf);
  // Shoulders 0.16 against 0.30 head heights apart (docs/features.md).
  const double native_apart = native.value().wrists[0].x() - native.value().wrists[1].x();
  const double asf_apart = asf.value().wrists[0].x() - asf.value().wrists[1].x();
  EXPECT_NEAR(native_apart, 0.16, 0.03);
  EXPECT_NEAR(asf_apart, 0.30, 0.03);
}

TEST(ArmsForward, APoseArmsForwardCannotGiveIsRefusedWithTheReason) {
  // The dancer standing with the arms down: wrists beside the hips, not in front.
  const LoadedMotion daz = salsa_take("01");
  Result<Clip> points = head_hands_clip(daz.clip, daz.roles);
  ASSERT_TRUE(points);
  points.value().keep_first_frames(30);
  Result<ArmsForward> held = arms_forward_of_points(points.value());
  ASSERT_FALSE(held);
  EXPECT_NE(held.error().message.find("in front of the head"), std::string::npos)
      << held.error().message;
  EXPECT_NE(held.error().message.find("arms held straight forward"), std::string::npos);

  ArmsForward crossed;
  crossed.wrists = {Vec3(-0.1, -0.2, 0.5), Vec3(0.1, -0.2, 0.5)};  // left hand on the right
  EXPECT_NE(crossed.check().find("apart"), std::string::npos) << crossed.check();
  ArmsForward not_numbers;
  not_numbers.wrists[0].x() = std::nan("");
  EXPECT_FALSE(not_numbers.check().empty());

  FollowSession session =
      hmm_session(head_hands_library(), make_head_hands_skeleton(), head_hands_roles());
  EXPECT_FALSE(session.set_arms_forward(crossed));
  EXPECT_FALSE(session.arms_forward().has_value());  // nothing changed
}

TEST(ArmsForward, CalibratedHandsOfAnotherRigMatchTheLibrarysRig) {
  // The same performance (take 60_15) as three points from the library's rig and from the ASF
  // rig: uncalibrated, the ASF hands sit 0.06-0.08 head heights off sideways on average; with
  // each body's calibration taken out (the session's hand offsets), within 0.03.
  const LoadedMotion daz = salsa_take("15");
  const LoadedMotion asf = on_asf_rig(daz);
  const DuetLibrary& library = head_hands_library();
  Result<ArmsForward> asf_pose = arms_forward_of_body(asf.clip, asf.roles, 10);
  ASSERT_TRUE(asf_pose);
  auto mean_hand_offset = [&](const std::optional<ArmsForward>& told) {
    Result<FeatureExtractor> native_x = library.make_extractor(daz.clip.skeleton_ptr(), daz.roles);
    Result<FeatureExtractor> asf_x = library.make_extractor(asf.clip.skeleton_ptr(), asf.roles);
    EXPECT_TRUE(native_x && asf_x);
    native_x.value().set_head_correction(head_correction(daz.clip, daz.roles).value());
    asf_x.value().set_head_correction(head_correction(asf.clip, asf.roles).value());
    FeatureExtractor::Context native_context = native_x.value().make_context();
    FeatureExtractor::Context asf_context = asf_x.value().make_context();
    if (told) {
      const ArmsForward& library_pose = library.template_arms_forward();
      asf_context.set_hand_offsets(
          {told->wrists[0] - library_pose.wrists[0], told->wrists[1] - library_pose.wrists[1]});
    }
    std::vector<float> a(static_cast<std::size_t>(native_x.value().dimension()));
    std::vector<float> b(a.size());
    double lateral = 0.0;
    const int frames = daz.clip.frame_count();
    for (int f = 0; f < frames; ++f) {
      native_x.value().extract(native_context, daz.clip.translations_ls(f),
                               daz.clip.rotations_ls(f), f / 60.0, a);
      asf_x.value().extract(asf_context, asf.clip.translations_ls(f), asf.clip.rotations_ls(f),
                            f / 60.0, b);
      lateral += 0.5 * (std::abs(b[0] - a[0]) + std::abs(b[3] - a[3]));  // the hands' x
    }
    return lateral / frames;
  };
  const double untold = mean_hand_offset(std::nullopt);
  const double told = mean_hand_offset(asf_pose.value());
  EXPECT_GT(untold, 0.05);
  EXPECT_LT(told, 0.03);
}

TEST(ArmsForward, AnotherRigCalibratedIsFollowedAsWellAsTheLibrarysOwn) {
  // Take 60_10 on the CMU handshake rig of 18_01 as three points, with a headset's noise, its head
  // height told either way: the calibration takes the rig's head, 0.05 head heights further
  // forward of its hands, and its wider shoulders to the library rig's hand places.
  const ThreePointsOnRig on_rig = take_10_on_handshake_rig_as_points();
  const Performance& points = on_rig.points;
  const ArmsForward& pose = on_rig.pose;
  const double head_m = on_rig.head_m;
  const Clip& clip = points.motion;
  auto within_100ms = [&](const std::optional<ArmsForward>& told) {
    FollowSession session = hmm_session(head_hands_library(), clip.skeleton_ptr(), points.roles);
    EXPECT_TRUE(session.set_head_height(head_m));
    EXPECT_TRUE(session.set_arms_forward(told));
    const int take = 8;  // 60_10
    int right = 0;
    for (int f = 0; f < clip.frame_count(); ++f) {
      const FollowResult r = session.step(clip.translations_ls(f), clip.rotations_ls(f), f / 60.0);
      right += r.take == take && std::abs(r.frame_in_take - f) <= 6 ? 1 : 0;
    }
    return static_cast<double>(right) / clip.frame_count();
  };
  const double untold = within_100ms(std::nullopt);
  const double told = within_100ms(pose);
  EXPECT_GT(told, 0.98) << "untold " << untold;  // measured 0.997
  EXPECT_LT(untold, 0.9);                        // measured 0.42
}

TEST(ArmsForward, TheHandsOffsetIsTheCalibrationsPlusWhatTheFollowerLearns) {
  // What the follower takes off each hand's place (FollowSession::hand_offsets, which the partner's
  // contact IK also takes as the body's part of the hand's difference): told, the calibration's
  // offset from the first frame; not told, the posture offset the follower learns, which on a rig
  // with wider shoulders (the CMU handshake rig, take 60_10 as three points) moves the hands
  // outwards as the calibration would.
  const ThreePointsOnRig on_rig = take_10_on_handshake_rig_as_points();
  const Performance& points = on_rig.points;
  const ArmsForward& pose = on_rig.pose;
  const double head_m = on_rig.head_m;
  const Clip& clip = points.motion;
  const ArmsForward& library_pose = head_hands_library().template_arms_forward();

  FollowSession told = hmm_session(head_hands_library(), clip.skeleton_ptr(), points.roles);
  ASSERT_TRUE(told.set_arms_forward(pose));
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_LT((told.hand_offsets()[s] - (pose.wrists[s] - library_pose.wrists[s])).norm(), 1e-12);
  }
  FollowSession untold = hmm_session(head_hands_library(), clip.skeleton_ptr(), points.roles);
  ASSERT_TRUE(untold.set_head_height(head_m));
  EXPECT_TRUE(untold.hand_offsets()[0].isZero());
  for (int f = 0; f < clip.frame_count(); ++f) {
    untold.step(clip.translations_ls(f), clip.rotations_ls(f), f / 60.0);
  }
  const std::array<Vec3, 2> learnt = untold.hand_offsets();
  for (std::size_t s = 0; s < 2; ++s) {
    const Vec3 calibration = pose.wrists[s] - library_pose.wrists[s];
    // Measured: calibration (0.059, -0.007, -0.057) and (-0.051, -0.003, -0.057) head heights,
    // learnt (0.073, 0.000, -0.044) and (-0.015, -0.005, -0.056).
    EXPECT_LT((learnt[s] - calibration).norm(), 0.5 * calibration.norm()) << "side " << s;
    EXPECT_GT(learnt[s].x() * calibration.x(), 0.0) << "side " << s;  // outwards, as told
  }
  // A full-body user has no hand places to offset.
  const LoadedMotion daz = salsa_take("10");
  FollowSession full = hmm_session(salsa_library(), daz.clip.skeleton_ptr(), daz.roles);
  EXPECT_TRUE(full.hand_offsets()[0].isZero() && full.hand_offsets()[1].isZero());
}

}  // namespace
}  // namespace duet::test
