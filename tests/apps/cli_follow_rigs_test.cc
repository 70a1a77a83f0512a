// duet follow with another rig in and out (issue 10): a user on the CMU ASF rig, the partner
// written on the handshake rig, and the exit code that says most of the input was lost.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "apps/run_command.h"
#include "duet/io/bvh.h"
#include "duet/io/motion_file.h"
#include "duet/math/rotation.h"
#include "duet/motion/body_space.h"
#include "duet/motion/forward_kinematics.h"
#include "duet/motion/up_axis.h"

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

TEST(CliFollowRigs, FootHoldIsOnByDefaultAndSwitchedOff) {
  // The foot hold (docs/partner.md, "Feet through a jump") is on by default and the summary names
  // it; --no-foot-hold switches it off.
  const std::filesystem::path out = temp_file("foothold.bvh");
  const std::string input = data_path("cmu-salsa/bvh/60/60_03_scaled.bvh");
  const testing::CommandResult on =
      run_duet("follow" + two_pairs() + " --input " + input + " --input-fps 60 -o " + out.string());
  ASSERT_EQ(on.exit_code, 0) << on.output;
  EXPECT_NE(on.output.find("corrections: align,contact,smooth,footlock,blend,foothold\n"),
            std::string::npos)
      << on.output;
  EXPECT_TRUE(std::filesystem::exists(out));
  const testing::CommandResult off = run_duet("follow" + two_pairs() + " --input " + input +
                                              " --input-fps 60 --no-foot-hold -o " + out.string());
  ASSERT_EQ(off.exit_code, 0) << off.output;
  EXPECT_NE(off.output.find("corrections: align,contact,smooth,footlock,blend\n"),
            std::string::npos)
      << off.output;
  // --foot-hold, its switch before it was on by default, is still accepted and changes nothing.
  const testing::CommandResult explicit_on =
      run_duet("follow" + two_pairs() + " --input " + input + " --input-fps 60 --foot-hold -o " +
               out.string());
  ASSERT_EQ(explicit_on.exit_code, 0) << explicit_on.output;
  EXPECT_NE(explicit_on.output.find("corrections: align,contact,smooth,footlock,blend,foothold\n"),
            std::string::npos)
      << explicit_on.output;
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

TEST(CliFollowRigs, AnInputMostlyStandingStillIsLostAndSaid) {
  // The Bandai dance as three points against the salsa library: its first 8.5 s stand, hands
  // hanging, like a salsa take's standing start; a dance moves on, so that is lost too, and named
  // as a cause.
  const std::string dance = data_path("bandai/dataset-1_dance-short_normal_001.bvh");
  const testing::CommandResult lost = run_duet("follow --library " + testing::kSalsaLibrary +
                                               " --input " + dance + " --input-points head,hands");
  EXPECT_EQ(lost.exit_code, 3) << lost.output;
  EXPECT_NE(lost.output.find("still: "), std::string::npos) << lost.output;
}

TEST(CliFollowRigs, AnInputAtTheWrongRateIsFollowedInFastMotionAndSaid) {
  // A 60 Hz take read at its header's 120 fps: followed at twice the tempo, no frame lost, so the
  // lost diagnosis never runs; the rate alone is warned of, with the rate to pass.
  const std::string input = data_path("cmu-salsa/bvh/60/60_03_scaled.bvh");
  const testing::CommandResult slow = run_duet("follow" + two_pairs() + " --input " + input);
  EXPECT_EQ(slow.exit_code, 0) << slow.output;
  EXPECT_NE(slow.output.find("warning: rate: the input was read at 120"), std::string::npos)
      << slow.output;
  EXPECT_NE(slow.output.find("pass --input-fps 60"), std::string::npos) << slow.output;
  const testing::CommandResult right =
      run_duet("follow" + two_pairs() + " --input " + input + " --input-fps 60");
  EXPECT_EQ(right.exit_code, 0) << right.output;
  EXPECT_EQ(right.output.find("rate:"), std::string::npos) << right.output;
}

TEST(CliFollowRigs, DancingThePartnersPartIsNamedAsTheLikelyCause) {
  // The follower's file given as the user's while the library expects the leader.
  const testing::CommandResult r =
      run_duet("follow" + two_pairs() + " --input " +
               data_path("cmu-salsa/bvh/61/61_03_scaled.bvh") + " --input-fps 60");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("--role partner"), std::string::npos) << r.output;
  // The same against a grown library: the other role is asked of the captured takes.
  const testing::CommandResult grown =
      run_duet("follow" + two_pairs() + " --grow-library 40000 --input " +
               data_path("cmu-salsa/bvh/61/61_03_scaled.bvh") + " --input-fps 60");
  EXPECT_EQ(grown.exit_code, 3) << grown.output;
  EXPECT_NE(grown.output.find("--role partner"), std::string::npos) << grown.output;
}

// The first `frames` frames of take `trial`'s leader, its world turned so that `up` is up, written
// as a BVH file in the take's units.
// The first `frames` of salsa take `trial`, written in a world turned by `y_up_to_file`.
std::filesystem::path write_take_in_world(const std::string& trial, const Quat& y_up_to_file,
                                          int frames, const std::string& name) {
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  Result<LoadedMotion> take =
      load_motion({data_path("cmu-salsa/bvh/60/60_" + trial + "_scaled.bvh")}, options);
  EXPECT_TRUE(take) << take.error().message;
  const Clip& whole = take.value().clip;
  Clip clip(whole.skeleton_ptr(), whole.frame_rate(), frames);
  for (int f = 0; f < frames; ++f) {
    std::ranges::copy(whole.translations_ls(f), clip.translations_ls(f).begin());
    std::ranges::copy(whole.rotations_ls(f), clip.rotations_ls(f).begin());
  }
  turn_world(clip, y_up_to_file);
  const std::filesystem::path path = temp_file(name);
  EXPECT_TRUE(
      write_bvh(clip, path.string(), BvhWriteOptions::in_file_units(take.value().metres_per_unit)));
  return path;
}

std::filesystem::path write_take_with_up(const std::string& trial, UpAxis up, int frames,
                                         const std::string& name) {
  return write_take_in_world(trial, rotation_to_y_up(up).conjugate(), frames, name);
}

TEST(CliFollowRigs, AZUpFileIsFollowedAndAnsweredInItsOwnWorld) {
  // 3ds Max, Motive and some Blender exports are Z-up. The same 15 s of take 01, Y-up and Z-up:
  // the Z-up one was 100 % lost before the up axis was read from the body.
  const std::filesystem::path y_up = write_take_with_up("01", UpAxis::kPosY, 900, "yup.bvh");
  const std::filesystem::path z_up = write_take_with_up("01", UpAxis::kPosZ, 900, "zup.bvh");
  const std::filesystem::path partner_y = temp_file("partner_y.bvh");
  const std::filesystem::path partner_z = temp_file("partner_z.bvh");
  const testing::CommandResult followed_y =
      run_duet("follow" + two_pairs() + " --input " + y_up.string() + " -o " + partner_y.string());
  const testing::CommandResult followed_z =
      run_duet("follow" + two_pairs() + " --input " + z_up.string() + " -o " + partner_z.string());
  ASSERT_EQ(followed_y.exit_code, 0) << followed_y.output;
  ASSERT_EQ(followed_z.exit_code, 0) << followed_z.output;
  EXPECT_NE(followed_z.output.find(" 0 lost frames"), std::string::npos) << followed_z.output;

  // The partner comes back in the input's world: Z-up, and once turned, the Y-up run's partner.
  Result<LoadedMotion> answer_y = load_motion({partner_y.string()});
  Result<LoadedMotion> answer_z = load_motion({partner_z.string()});
  ASSERT_TRUE(answer_y) << answer_y.error().message;
  ASSERT_TRUE(answer_z) << answer_z.error().message;
  EXPECT_EQ(answer_y.value().up_axis, UpAxis::kPosY);
  EXPECT_EQ(answer_z.value().up_axis, UpAxis::kPosZ);
  EXPECT_EQ(answer_z.value().up_source, "read from the body");
  const std::vector<Vec3> a = world_positions(answer_y.value().clip);
  const std::vector<Vec3> b = world_positions(answer_z.value().clip);
  ASSERT_EQ(a.size(), b.size());
  double largest = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) largest = std::max(largest, (a[i] - b[i]).norm());
  EXPECT_LT(largest, 0.002) << "metres";

  const testing::CommandResult inspected = run_duet("inspect " + z_up.string());
  EXPECT_NE(inspected.output.find("up axis:     +Z, read from the body"), std::string::npos)
      << inspected.output;
  // Told the wrong axis, it is lost, and the cause says what was given.
  const testing::CommandResult told_wrong =
      run_duet("follow" + two_pairs() + " --input " + z_up.string() + " --input-up y");
  EXPECT_EQ(told_wrong.exit_code, 3) << told_wrong.output;
  EXPECT_NE(told_wrong.output.find("up axis: +Y was given"), std::string::npos)
      << told_wrong.output;
  for (const auto& path : {y_up, z_up, partner_y, partner_z}) std::filesystem::remove(path);
}

TEST(CliFollowRigs, ATiltedFloorIsLevelledAndThePartnerAnswersOnIt) {
  // A camera pitched down, or a pose estimator's camera frame, sees the floor tilted. Take 01,
  // Z-up and tilted 12 degrees: before levelling, 10 degrees cost 30 points in `duet eval`.
  const Quat tilt(Eigen::AngleAxisd(deg_to_rad(12.0), Vec3(1.0, 0.0, 1.0).normalized()));
  const Quat y_up_to_file = rotation_to_y_up(UpAxis::kPosZ).conjugate() * tilt;
  const std::filesystem::path y_up = write_take_with_up("01", UpAxis::kPosY, 900, "flat.bvh");
  const std::filesystem::path tilted = write_take_in_world("01", y_up_to_file, 900, "tilted.bvh");
  const std::filesystem::path partner_y = temp_file("partner_flat.bvh");
  const std::filesystem::path partner_t = temp_file("partner_tilted.bvh");
  const testing::CommandResult followed_y =
      run_duet("follow" + two_pairs() + " --input " + y_up.string() + " -o " + partner_y.string());
  const testing::CommandResult followed_t = run_duet("follow" + two_pairs() + " --input " +
                                                     tilted.string() + " -o " + partner_t.string());
  ASSERT_EQ(followed_y.exit_code, 0) << followed_y.output;
  ASSERT_EQ(followed_t.exit_code, 0) << followed_t.output;
  EXPECT_NE(followed_t.output.find(" 0 lost frames"), std::string::npos) << followed_t.output;

  Result<LoadedMotion> input = load_motion({tilted.string()});
  ASSERT_TRUE(input) << input.error().message;
  EXPECT_EQ(input.value().up_axis, UpAxis::kPosZ);
  // The tilt read from the body: 12 degrees, give or take the dancer's own mean lean (1.5).
  EXPECT_NEAR(input.value().tilt_deg(), 12.0, 3.0);
  EXPECT_NE(input.value().up_source.find("levelled by"), std::string::npos)
      << input.value().up_source;

  // The partner comes back on the tilted floor: turned out of that world with the true turn, it
  // is the level run's partner, up to the levelling's error (the lean) over the partner's reach.
  MotionLoadOptions as_written;
  as_written.up_axis = UpAxis::kPosY;  // read the files' worlds as they are
  Result<LoadedMotion> answer_y = load_motion({partner_y.string()}, as_written);
  Result<LoadedMotion> answer_t = load_motion({partner_t.string()}, as_written);
  ASSERT_TRUE(answer_y) << answer_y.error().message;
  ASSERT_TRUE(answer_t) << answer_t.error().message;
  Clip answer = answer_t.value().clip;
  turn_world(answer, y_up_to_file.conjugate());
  const std::vector<Vec3> a = world_positions(answer_y.value().clip);
  const std::vector<Vec3> b = world_positions(answer);
  ASSERT_EQ(a.size(), b.size());
  std::vector<double> distances;
  for (std::size_t i = 0; i < a.size(); ++i) distances.push_back((a[i] - b[i]).norm());
  std::ranges::nth_element(distances, distances.begin() + distances.size() / 2);
  EXPECT_LT(distances[distances.size() / 2], 0.05) << "metres, median";

  const testing::CommandResult inspected = run_duet("inspect " + tilted.string());
  EXPECT_NE(inspected.output.find("a tilted floor, levelled by"), std::string::npos)
      << inspected.output;
  for (const auto& path : {y_up, tilted, partner_y, partner_t}) std::filesystem::remove(path);
}

}  // namespace
}  // namespace duet
