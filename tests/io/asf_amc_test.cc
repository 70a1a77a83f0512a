// Tests of the ASF/AMC reader: the math on a tiny synthetic skeleton, one test per malformed input
// (each asserting the whole "file:line: reason" message), and the real CMU files against the
// independent conversion in crosscheck/cmu_60_01.bvh.
#include "duet/io/asf_amc.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "duet/io/bvh.h"
#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"

namespace duet {
namespace {

const std::string kTestdata = std::string(DUET_TESTDATA_DIR) + "/asf/";
const std::string kCmu = std::string(DUET_DATA_DIR) + "/cmu-salsa/asf-amc/";
const std::string kCrosscheck = std::string(DUET_DATA_DIR) + "/crosscheck/cmu_60_01.bvh";
constexpr double kCmuMetresPerUnit = 0.0254 / 0.45;

// Rotation by `deg` degrees about a principal axis.
Quat rot(int axis, double deg) {
  return Quat(Eigen::AngleAxisd(deg * kPi / 180.0, Vec3::Unit(axis)));
}
constexpr int X = 0, Y = 1, Z = 2;

double angle_deg(const Quat& a, const Quat& b) { return a.angularDistance(b) * 180.0 / kPi; }

std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

// A small valid ASF: root, bone `a` (3 DOF) and bone `b` (no DOF, like lhipjoint).
std::vector<std::string> mini_asf() {
  return {
      ":units",                     // 1
      "  length 1",                 // 2
      "  angle deg",                // 3
      ":root",                      // 4
      "  order TX TY TZ RX RY RZ",  // 5
      "  axis XYZ",                 // 6
      "  position 0 0 0",           // 7
      "  orientation 0 0 0",        // 8
      ":bonedata",                  // 9
      "  begin",                    // 10
      "    name a",                 // 11
      "    direction 0 1 0",        // 12
      "    length 1",               // 13
      "    axis 0 0 0 XYZ",         // 14
      "    dof rx ry rz",           // 15
      "  end",                      // 16
      "  begin",                    // 17
      "    name b",                 // 18
      "    direction 0 1 0",        // 19
      "    length 1",               // 20
      "    axis 0 0 0 XYZ",         // 21
      "  end",                      // 22
      ":hierarchy",                 // 23
      "  begin",                    // 24
      "    root a",                 // 25
      "    a b",                    // 26
      "  end",                      // 27
  };
}

std::vector<std::string> mini_amc() {
  return {
      ":FULLY-SPECIFIED",  // 1
      ":DEGREES",          // 2
      "1",                 // 3
      "root 0 0 0 0 0 0",  // 4
      "a 0 0 0",           // 5
      "2",                 // 6
      "root 0 0 0 0 0 0",  // 7
      "a 0 0 0",           // 8
  };
}

Result<Clip> parse_mini(const std::vector<std::string>& asf, const std::vector<std::string>& amc,
                        const AsfAmcReadOptions& options = {}) {
  return parse_asf_amc(join_lines(asf), "t.asf", join_lines(amc), "t.amc", options);
}

// The error message, or "ok".
std::string message(const Result<Clip>& result) {
  return result ? std::string("ok") : result.error().message;
}

std::string asf_error(std::vector<std::string> asf) { return message(parse_mini(asf, mini_amc())); }
std::string amc_error(std::vector<std::string> amc, const AsfAmcReadOptions& options = {}) {
  return message(parse_mini(mini_asf(), amc, options));
}

// ----------------------------------------------------------------------------- valid input

TEST(AsfAmc, MiniFileLoads) {
  const Result<Clip> clip = parse_mini(mini_asf(), mini_amc());
  ASSERT_TRUE(clip) << clip.error().message;
  EXPECT_EQ(clip.value().frame_count(), 2);
  EXPECT_EQ(clip.value().frame_rate(), 120.0);
  EXPECT_EQ(clip.value().skeleton().validate(), "");
}

class TinyFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    AsfAmcReadOptions options;
    options.frame_rate = 60.0;
    Result<Clip> result = read_asf_amc(kTestdata + "tiny.asf", kTestdata + "tiny.amc", options);
    ASSERT_TRUE(result) << result.error().message;
    clip = std::move(result).value();
  }
  int joint(const char* name) const {
    const int j = clip.skeleton().find(name);
    EXPECT_GE(j, 0) << name;
    return j;
  }
  Clip clip;
  // `:units length 0.5`: metres = value / 0.5 * 0.0254.
  static constexpr double kScale = 0.0254 / 0.5;
};

TEST_F(TinyFixture, Structure) {
  const Skeleton& s = clip.skeleton();
  EXPECT_EQ(s.validate(), "");
  EXPECT_EQ(clip.frame_count(), 3);
  EXPECT_EQ(clip.frame_rate(), 60.0);
  // Depth first in :hierarchy order, an End Site after each leaf bone.
  const std::vector<std::string> names = {"root",     "hip",   "thigh",    "shin",
                                          "shin_End", "spine", "spine_End"};
  ASSERT_EQ(s.joint_count(), static_cast<int>(names.size()));
  for (int j = 0; j < s.joint_count(); ++j)
    EXPECT_EQ(s.joints[static_cast<std::size_t>(j)].name, names[static_cast<std::size_t>(j)]);
  const std::vector<int> parents = {-1, 0, 1, 2, 3, 0, 5};
  for (int j = 0; j < s.joint_count(); ++j)
    EXPECT_EQ(s.joints[static_cast<std::size_t>(j)].parent, parents[static_cast<std::size_t>(j)]);
  EXPECT_TRUE(s.joints[4].end_site);
  EXPECT_TRUE(s.joints[6].end_site);
  // Root: 6 channels; every bone, with or without DOF, 3 rotation channels (like CMU's BVH).
  EXPECT_EQ(s.joints[0].channels.size(), 6u);
  EXPECT_TRUE(s.joints[0].has_position_channels());
  for (const char* bone : {"hip", "thigh", "shin", "spine"}) {
    const Joint& j = s.joints[static_cast<std::size_t>(joint(bone))];
    EXPECT_EQ(j.channels,
              (std::vector<Channel>{Channel::kXrotation, Channel::kYrotation, Channel::kZrotation}))
        << bone;
  }
  EXPECT_TRUE(s.joints[4].channels.empty());
}

TEST_F(TinyFixture, OffsetsAreParentBoneVectorsInMetres) {
  const Skeleton& s = clip.skeleton();
  auto offset = [&](const char* name) {
    return s.joints[static_cast<std::size_t>(joint(name))].offset;
  };
  // A joint sits at the start of its bone: its offset is the parent bone's direction * length.
  EXPECT_TRUE(offset("hip").isZero());
  EXPECT_TRUE(offset("spine").isZero());
  EXPECT_TRUE(offset("thigh").isApprox(Vec3(2, 0, 0) * kScale));
  EXPECT_TRUE(offset("shin").isApprox(Vec3(0, -4, 0) * kScale));
  EXPECT_TRUE(offset("shin_End").isApprox(Vec3(0, -4, 0) * kScale));
  EXPECT_TRUE(offset("spine_End").isApprox(Vec3(0, 3, 0) * kScale));
}

TEST_F(TinyFixture, FirstFrameIsRestPoseAtRootPosition) {
  const auto r = clip.rotations_ls(0);
  for (const Quat& q : r) EXPECT_LT(angle_deg(q, Quat::Identity()), 1e-9);
  EXPECT_TRUE(clip.translations_ls(0)[0].isApprox(Vec3(0, 2, 0) * kScale));
}

TEST_F(TinyFixture, LocalRotationIsAxisConjugatedMotion) {
  const auto r = clip.rotations_ls(1);
  // Root: `order ... RX RY RZ` applies X first: R = Rz * Ry * Rx. -854.4 deg is just composed.
  EXPECT_LT(angle_deg(r[0], rot(Z, 10) * rot(Y, 90) * rot(X, -854.4)), 1e-9);
  EXPECT_LT(angle_deg(r[0], rot(Z, 10) * rot(Y, 90) * rot(X, -854.4 + 720.0)), 1e-9);
  // thigh: C = Rz(90) (axis 0 0 90 XYZ), M = Rz(30) Ry(20) Rx(10), L = C M C^-1.
  const Quat c_leg = rot(Z, 90);
  const Quat thigh = c_leg * rot(Z, 30) * rot(Y, 20) * rot(X, 10) * c_leg.conjugate();
  EXPECT_LT(angle_deg(r[static_cast<std::size_t>(joint("thigh"))], thigh), 1e-9);
  // shin: one DOF about the bone's x axis, which C turns onto world +Y.
  EXPECT_LT(angle_deg(r[static_cast<std::size_t>(joint("shin"))], rot(Y, 45)), 1e-9);
  // spine: `axis 30 -20 10 ZYX` applies z first: C = Rx(30) Ry(-20) Rz(10); `dof rz rx` with
  // values 15 -25 applies rz first: M = Rx(-25) Rz(15).
  const Quat c_spine = rot(X, 30) * rot(Y, -20) * rot(Z, 10);
  const Quat spine = c_spine * rot(X, -25) * rot(Z, 15) * c_spine.conjugate();
  EXPECT_LT(angle_deg(r[static_cast<std::size_t>(joint("spine"))], spine), 1e-9);
  // hip has no DOF and no AMC line.
  EXPECT_LT(angle_deg(r[static_cast<std::size_t>(joint("hip"))], Quat::Identity()), 1e-12);
  // Root translation: AMC values in ASF length units.
  EXPECT_TRUE(clip.translations_ls(1)[0].isApprox(Vec3(1, 2, 3) * kScale));
}

TEST_F(TinyFixture, BoneLinesInAnyOrderAndWorldPositions) {
  // Frame 3 lists spine before the leg; the shin is straight out along the thigh's direction.
  const std::vector<Vec3> p = world_positions(clip);
  const auto n = static_cast<std::size_t>(clip.joint_count());
  const Vec3* f = p.data() + 2 * n;
  const Quat root = rot(Z, 0) * rot(Y, -30) * rot(X, 440.8);
  const Vec3 root_t = Vec3(-1, 1.5, 0.5) * kScale;
  const Quat c_leg = rot(Z, 90);
  const Quat thigh = c_leg * rot(Z, -90) * c_leg.conjugate();
  const Quat shin = c_leg * rot(X, 90) * c_leg.conjugate();
  const Vec3 hip_tip = root_t + root * Vec3(2, 0, 0) * kScale;
  const Vec3 knee = hip_tip + root * thigh * Vec3(0, -4, 0) * kScale;
  const Vec3 ankle = knee + root * thigh * shin * Vec3(0, -4, 0) * kScale;
  EXPECT_LT((f[joint("thigh")] - hip_tip).norm(), 1e-12);
  EXPECT_LT((f[joint("shin")] - knee).norm(), 1e-12);
  EXPECT_LT((f[joint("shin_End")] - ankle).norm(), 1e-12);
}

TEST(AsfAmc, CrlfAndLfGiveTheSameClip) {
  const std::string asf = join_lines(mini_asf());
  const std::string amc = join_lines({"1", "root 1 2 3 4 5 6", "a 7 8 9"});
  auto crlf = [](std::string text) {
    std::string out;
    for (const char c : text) out += c == '\n' ? std::string("\r\n") : std::string(1, c);
    return out;
  };
  const Result<Clip> a = parse_asf_amc(asf, "a.asf", amc, "a.amc");
  const Result<Clip> b = parse_asf_amc(crlf(asf), "b.asf", crlf(amc), "b.amc");
  ASSERT_TRUE(a && b);
  for (int j = 0; j < a.value().joint_count(); ++j) {
    EXPECT_EQ(a.value().translations_ls(0)[static_cast<std::size_t>(j)],
              b.value().translations_ls(0)[static_cast<std::size_t>(j)]);
    EXPECT_EQ(a.value().rotations_ls(0)[static_cast<std::size_t>(j)].coeffs(),
              b.value().rotations_ls(0)[static_cast<std::size_t>(j)].coeffs());
  }
}

TEST(AsfAmc, UnitsAndMetresPerUnitOverride) {
  std::vector<std::string> asf = mini_asf();
  asf[1] = "  length 0.45";
  const Result<Clip> cmu = parse_mini(asf, {"1", "root 0.45 0 0 0 0 0", "a 0 0 0"});
  ASSERT_TRUE(cmu) << cmu.error().message;
  EXPECT_NEAR(cmu.value().skeleton().joints[2].offset.y(), kCmuMetresPerUnit, 1e-15);
  EXPECT_NEAR(cmu.value().translations_ls(0)[0].x(), 0.0254, 1e-15);
  AsfAmcReadOptions options;
  options.metres_per_unit = 1.0;  // metres per unit once `length` is undone
  const Result<Clip> own = parse_mini(asf, {"1", "root 0.45 0 0 0 0 0", "a 0 0 0"}, options);
  ASSERT_TRUE(own);
  EXPECT_NEAR(own.value().skeleton().joints[2].offset.y(), 1.0 / 0.45, 1e-12);
  EXPECT_NEAR(own.value().translations_ls(0)[0].x(), 1.0, 1e-12);
}

TEST(AsfAmc, RootPositionOrientationAndOrder) {
  std::vector<std::string> asf = mini_asf();
  asf[4] = "  order RZ TX RY TY RX TZ";
  asf[6] = "  position 1 2 3";
  asf[7] = "  orientation 0 90 0";
  AsfAmcReadOptions options;
  options.metres_per_unit = 1.0;
  const Result<Clip> clip = parse_mini(asf, {"1", "root 30 10 20 20 10 30", "a 0 0 0"}, options);
  ASSERT_TRUE(clip) << clip.error().message;
  EXPECT_TRUE(clip.value().skeleton().joints[0].offset.isApprox(Vec3(1, 2, 3)));
  EXPECT_TRUE(clip.value().translations_ls(0)[0].isApprox(Vec3(11, 22, 33)));
  // Rotations applied in the order `order` lists them (RZ, RY, RX), conjugated by C = Ry(90).
  const Quat c = rot(Y, 90);
  const Quat expected = c * rot(X, 10) * rot(Y, 20) * rot(Z, 30) * c.conjugate();
  EXPECT_LT(angle_deg(clip.value().rotations_ls(0)[0], expected), 1e-9);
}

TEST(AsfAmc, RadiansInAsfAndAmc) {
  std::vector<std::string> asf = mini_asf();
  asf[2] = "  angle rad";
  asf[13] = "    axis 0 0 1.5707963267948966 XYZ";
  // No :DEGREES/:RADIANS in the AMC: the ASF's unit applies.
  const Result<Clip> a = parse_mini(asf, {"1", "root 0 0 0 0 0 0", "a 0.5 0 0"});
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_LT(angle_deg(a.value().rotations_ls(0)[1], rot(Y, 0.5 * 180.0 / kPi)), 1e-9);
  // :DEGREES in the AMC wins over the ASF's radians.
  const Result<Clip> b = parse_mini(asf, {":DEGREES", "1", "root 0 0 0 0 0 0", "a 30 0 0"});
  ASSERT_TRUE(b);
  EXPECT_LT(angle_deg(b.value().rotations_ls(0)[1], rot(Y, 30)), 1e-9);
  // And :RADIANS over the ASF's degrees.
  const Result<Clip> c = parse_mini(mini_asf(), {":RADIANS", "1", "root 0 0 0 0 0 1", "a 0 0 0"});
  ASSERT_TRUE(c);
  EXPECT_LT(angle_deg(c.value().rotations_ls(0)[0], rot(Z, 180.0 / kPi)), 1e-9);
}

TEST(AsfAmc, TranslationAndLengthDof) {
  std::vector<std::string> asf = mini_asf();
  asf[13] = "    axis 0 0 90 XYZ";
  asf[14] = "    dof tx l";
  AsfAmcReadOptions options;
  options.metres_per_unit = 1.0;
  const Result<Clip> clip = parse_mini(asf, {"1", "root 0 0 0 0 0 0", "a 2 0.5"}, options);
  ASSERT_TRUE(clip) << clip.error().message;
  const Skeleton& s = clip.value().skeleton();
  // tx moves bone a along its own x axis, which C = Rz(90) turns onto world +Y.
  EXPECT_TRUE(clip.value().translations_ls(0)[1].isApprox(Vec3(0, 2, 0)));
  // l stretches bone a: its child b starts 1.5 units up instead of 1.
  EXPECT_TRUE(clip.value().translations_ls(0)[static_cast<std::size_t>(s.find("b"))].isApprox(
      Vec3(0, 1.5, 0)));
  EXPECT_TRUE(s.joints[1].has_position_channels());
  EXPECT_TRUE(s.joints[2].has_position_channels());
}

TEST(AsfAmc, BoneWithoutDofMayHaveAnEmptyLine) {
  std::vector<std::string> amc = mini_amc();
  amc.insert(amc.begin() + 5, "b");
  EXPECT_EQ(amc_error(amc), "ok");
}

TEST(AsfAmc, FirstFrameNumberIsFreeAndNeverSizesAnything) {
  // A file may start at any frame number; 10^12 allocates nothing, it is only counted from.
  const Result<Clip> clip =
      parse_mini(mini_asf(), {"1000000000000", "root 0 0 0 0 0 0", "a 0 0 0", "1000000000001",
                              "root 0 0 0 0 0 0", "a 0 0 0"});
  ASSERT_TRUE(clip) << clip.error().message;
  EXPECT_EQ(clip.value().frame_count(), 2);
}

TEST(AsfAmc, CommentsKeywordsAndLimitsAcrossLines) {
  std::vector<std::string> asf = mini_asf();
  asf.insert(asf.begin() + 15, "    limits (-inf inf)");
  asf.insert(asf.begin() + 16, "           ( -70.0 70.0 )");
  asf.insert(asf.begin() + 17, "           (-60.0 70.0)");
  asf.insert(asf.begin(), "# a comment");
  asf.insert(asf.begin() + 1, ":version 1.10");
  asf.insert(asf.begin() + 2, ":name VICON");
  asf.insert(asf.begin() + 3, ":documentation");
  asf.insert(asf.begin() + 4, "   free text, even: 1 2 3 begin end");
  EXPECT_EQ(message(parse_mini(asf, mini_amc())), "ok");
}

// ----------------------------------------------------------------------------- malformed input

TEST(AsfAmcErrors, MissingFiles) {
  const Result<Clip> asf = read_asf_amc(kTestdata + "missing.asf", kTestdata + "tiny.amc");
  ASSERT_FALSE(asf);
  EXPECT_EQ(asf.error().message, kTestdata + "missing.asf: cannot open: No such file or directory");
  const Result<Clip> amc = read_asf_amc(kTestdata + "tiny.asf", kTestdata + "missing.amc");
  ASSERT_FALSE(amc);
  EXPECT_EQ(amc.error().message, kTestdata + "missing.amc: cannot open: No such file or directory");
}

TEST(AsfAmcErrors, EmptyFiles) {
  EXPECT_EQ(message(parse_asf_amc("", "e.asf", join_lines(mini_amc()), "t.amc")),
            "e.asf: empty file");
  EXPECT_EQ(message(parse_asf_amc(join_lines(mini_asf()), "t.asf", " \r\n\n", "e.amc")),
            "e.amc: empty file");
  EXPECT_EQ(amc_error({":FULLY-SPECIFIED", ":DEGREES"}), "t.amc:2: no frames");
}

TEST(AsfAmcErrors, UnknownKeywordsAndFields) {
  std::vector<std::string> asf = mini_asf();
  asf.insert(asf.begin() + 3, ":skeleton");
  EXPECT_EQ(asf_error(asf), "t.asf:4: unknown keyword ':skeleton'");
  asf = mini_asf();
  asf[1] = "  size 1";
  EXPECT_EQ(asf_error(asf), "t.asf:2: unknown :units field 'size'");
  asf = mini_asf();
  asf[2] = "  angle grad";
  EXPECT_EQ(asf_error(asf), "t.asf:3: angle unit must be 'deg' or 'rad', found 'grad'");
  asf = mini_asf();
  asf[5] = "  position 0 0 0";
  asf[6] = "  colour red";
  EXPECT_EQ(asf_error(asf), "t.asf:7: unknown :root field 'colour'");
  asf = mini_asf();
  asf[13] = "    twist 3";
  EXPECT_EQ(asf_error(asf), "t.asf:14: unknown bone field 'twist'");
  asf = mini_asf();
  asf[14] = "    dof rx rw";
  EXPECT_EQ(asf_error(asf), "t.asf:15: dof: expected rx, ry, rz, tx, ty, tz or l, found 'rw'");
  asf = mini_asf();
  asf[13] = "    axis 0 0 0 XYY";
  EXPECT_EQ(asf_error(asf), "t.asf:14: axis: expected an order such as XYZ, found 'XYY'");
  asf = mini_asf();
  asf.insert(asf.begin(), "hello");
  EXPECT_EQ(asf_error(asf), "t.asf:1: expected a ':' keyword, found 'hello'");
  EXPECT_EQ(amc_error({":FULLY-SPECIFIED", ":DEGREEZ", "1", "root 0 0 0 0 0 0", "a 0 0 0"}),
            "t.amc:2: unknown keyword ':DEGREEZ'");
}

TEST(AsfAmcErrors, BoneBlocks) {
  std::vector<std::string> asf = mini_asf();
  asf[15] = "    id 3";  // `end` of bone a missing: the next `begin` is a field
  EXPECT_EQ(asf_error(asf), "t.asf:17: unknown bone field 'begin'");
  asf = mini_asf();
  asf.resize(21);  // file ends inside bone b
  EXPECT_EQ(asf_error(asf), "t.asf:17: bone block has no 'end'");
  asf = mini_asf();
  asf[10] = "    id 1";
  EXPECT_EQ(asf_error(asf), "t.asf:10: bone has no name");
  asf = mini_asf();
  asf[17] = "    name a";
  EXPECT_EQ(asf_error(asf), "t.asf:17: bone name 'a' is used twice");
  asf = mini_asf();
  asf[17] = "    name root";
  EXPECT_EQ(asf_error(asf), "t.asf:17: bone name 'root' is used twice (root is the root's name)");
  asf = mini_asf();
  asf[19] = "    id 2";
  EXPECT_EQ(asf_error(asf), "t.asf:17: bone 'b' has no length");
  asf = mini_asf();
  asf.insert(asf.begin() + 15, "    limits (-10 10) (-20 20)");
  EXPECT_EQ(asf_error(asf),
            "t.asf:10: bone 'a' has 3 DOF but 4 limit values (expected one pair per DOF)");
  asf = mini_asf();
  asf.erase(asf.begin() + 3, asf.begin() + 8);
  EXPECT_EQ(asf_error(asf), "t.asf: no :root section");
}

TEST(AsfAmcErrors, HierarchyNamesUndefinedBone) {
  std::vector<std::string> asf = mini_asf();
  asf[25] = "    a b c";
  EXPECT_EQ(asf_error(asf), "t.asf:26: hierarchy names bone 'c', which :bonedata does not define");
  asf[25] = "    x b";
  EXPECT_EQ(asf_error(asf), "t.asf:26: hierarchy names bone 'x', which :bonedata does not define");
}

TEST(AsfAmcErrors, HierarchyCycleAndTwoParents) {
  std::vector<std::string> asf = mini_asf();
  asf[24] = "    root b";
  asf[25] = "    a b";
  EXPECT_EQ(asf_error(asf), "t.asf:26: bone 'b' has two parents: 'root' (line 25) and 'a'");
  asf[24] = "    b a";
  EXPECT_EQ(asf_error(asf), "t.asf:25: hierarchy has a cycle through bone 'a'");
  asf[24] = "    root b";
  asf[25] = "    a a";
  EXPECT_EQ(asf_error(asf), "t.asf:26: bone 'a' is its own parent");
  asf[24] = "    b root";
  EXPECT_EQ(asf_error(asf), "t.asf:25: root cannot be a child");
  asf = mini_asf();
  asf.erase(asf.begin() + 25);  // b never gets a parent
  EXPECT_EQ(asf_error(asf), "t.asf:17: bone 'b' is not in the :hierarchy");
  // a hangs under b, which the hierarchy never places (found by the fuzzer: the walk up from a
  // ran off the root-less b).
  asf = mini_asf();
  asf[24] = "    b a";
  asf.erase(asf.begin() + 25);
  EXPECT_EQ(asf_error(asf), "t.asf:17: bone 'b' is not in the :hierarchy");
  asf = mini_asf();
  asf.resize(26);
  EXPECT_EQ(asf_error(asf), "t.asf:23: :hierarchy has no 'end'");
}

TEST(AsfAmcErrors, NonNumbers) {
  std::vector<std::string> asf = mini_asf();
  asf[12] = "    length one";
  EXPECT_EQ(asf_error(asf), "t.asf:13: expected a number, found 'one'");
  asf[12] = "    length 1 2";
  EXPECT_EQ(asf_error(asf), "t.asf:13: expected 1 number after 'length', found 2");
  asf[12] = "    length 1";
  asf[11] = "    direction 0 1";
  EXPECT_EQ(asf_error(asf), "t.asf:12: expected 3 numbers after 'direction', found 2");
  asf[11] = "    direction 0 1 0x1";
  EXPECT_EQ(asf_error(asf), "t.asf:12: expected a number, found '0x1'");
  std::vector<std::string> amc = mini_amc();
  amc[7] = "a 0 1.5.2 0";
  EXPECT_EQ(amc_error(amc), "t.amc:8: expected a number, found '1.5.2'");
  amc[7] = "a 0 -- 0";
  EXPECT_EQ(amc_error(amc), "t.amc:8: expected a number, found '--'");
}

TEST(AsfAmcErrors, NanAndInfinity) {
  std::vector<std::string> asf = mini_asf();
  asf[11] = "    direction 0 nan 0";
  EXPECT_EQ(asf_error(asf), "t.asf:12: 'nan' is not a finite number");
  asf[11] = "    direction 0 1e999 0";
  EXPECT_EQ(asf_error(asf), "t.asf:12: '1e999' is not a finite number");
  std::vector<std::string> amc = mini_amc();
  amc[7] = "a 0 inf 0";
  EXPECT_EQ(amc_error(amc), "t.amc:8: 'inf' is not a finite number");
  amc[7] = "a 0 -NaN 0";
  EXPECT_EQ(amc_error(amc), "t.amc:8: '-NaN' is not a finite number");
  // Underflow is just zero.
  amc[7] = "a 0 1e-999 0";
  EXPECT_EQ(amc_error(amc), "ok");
  // Finite values whose sum overflows are caught when the clip is built.
  asf[11] = "    direction 0 1 0";
  asf[6] = "  position 1e308 0 0";
  AsfAmcReadOptions options;
  options.metres_per_unit = 1.0;
  EXPECT_EQ(message(parse_mini(asf, {"1", "root 1e308 0 0 0 0 0", "a 0 0 0"}, options)),
            "t.amc:1: bone 'root' has a non-finite transform (values too large)");
}

TEST(AsfAmcErrors, AmcLineWithWrongValueCount) {
  std::vector<std::string> amc = mini_amc();
  amc[7] = "a 0 0";
  EXPECT_EQ(amc_error(amc), "t.amc:8: bone 'a' has 3 DOF but the line has 2 values");
  amc[7] = "a 0 0 0 0";
  EXPECT_EQ(amc_error(amc), "t.amc:8: bone 'a' has 3 DOF but the line has 4 values");
  amc[7] = "b 1";
  EXPECT_EQ(amc_error(amc), "t.amc:8: bone 'b' has 0 DOF but the line has 1 value");
  amc[7] = "root 0 0 0 0 0";
  EXPECT_EQ(amc_error(amc), "t.amc:8: bone 'root' given twice in frame 2");
  amc = mini_amc();
  amc[6] = "root 0 0 0 0 0";
  EXPECT_EQ(amc_error(amc), "t.amc:7: bone 'root' has 6 DOF but the line has 5 values");
}

TEST(AsfAmcErrors, AmcBoneNotInAsf) {
  std::vector<std::string> amc = mini_amc();
  amc[7] = "lfemur 0 0 0";
  EXPECT_EQ(amc_error(amc), "t.amc:8: bone 'lfemur' is not in the ASF");
  amc = mini_amc();
  amc.insert(amc.begin() + 2, "a 0 0 0");
  EXPECT_EQ(amc_error(amc), "t.amc:3: bone line before the first frame number");
}

TEST(AsfAmcErrors, FrameNumbersOutOfOrderOrWithGaps) {
  std::vector<std::string> amc = mini_amc();
  amc[5] = "1";
  EXPECT_EQ(amc_error(amc), "t.amc:6: expected frame 2 after frame 1, found '1' (out of order)");
  amc[5] = "3";
  EXPECT_EQ(amc_error(amc), "t.amc:6: expected frame 2 after frame 1, found '3' (a gap)");
  amc[5] = "1000000000000";
  EXPECT_EQ(amc_error(amc),
            "t.amc:6: expected frame 2 after frame 1, found '1000000000000' (a gap)");
  amc[5] = "99999999999999999999999";
  EXPECT_EQ(amc_error(amc), "t.amc:6: frame number '99999999999999999999999' is out of range");
  amc[5] = "-2";
  EXPECT_EQ(amc_error(amc), "t.amc:6: frame number '-2' is negative");
  amc[5] = "-0";  // found by the fuzzer: from_chars reads it as 0
  EXPECT_EQ(amc_error(amc), "t.amc:6: frame number '-0' is negative");
  amc[5] = "2x";
  EXPECT_EQ(amc_error(amc), "t.amc:6: expected a frame number, found '2x'");
  amc = mini_amc();
  amc.pop_back();  // frame 2 lacks bone a
  EXPECT_EQ(amc_error(amc), "t.amc:6: frame 2 has no line for bone 'a'");
  amc.push_back("3");
  EXPECT_EQ(amc_error(amc), "t.amc:6: frame 2 has no line for bone 'a'");
}

TEST(AsfAmcErrors, MaxFrames) {
  AsfAmcReadOptions options;
  options.max_frames = 1;
  EXPECT_EQ(amc_error(mini_amc(), options),
            "t.amc:6: too many frames: the limit is 1 (AsfAmcReadOptions::max_frames)");
}

TEST(AsfAmcErrors, BinaryGarbage) {
  const std::string garbage(
      "\x7f"
      "ELF\x02\x01\x01\x00\x00\x00\xff\xfe",
      12);
  EXPECT_EQ(message(parse_asf_amc(garbage, "g.asf", join_lines(mini_amc()), "t.amc")),
            "g.asf:1: control byte 0x7f in text (binary data?)");
  EXPECT_EQ(message(parse_asf_amc(join_lines(mini_asf()), "t.asf", "1\nroot \x01", "g.amc")),
            "g.amc:2: control byte 0x01 in text (binary data?)");
  std::vector<std::string> asf = mini_asf();
  asf[10] = std::string("    name a\0b", 12);
  EXPECT_EQ(asf_error(asf), "t.asf:11: control byte 0x00 in text (binary data?)");
  // Bytes >= 0x80 are not control bytes (UTF-8 names and comments); they are just not numbers.
  std::vector<std::string> amc = mini_amc();
  amc[7] = "a 0 \xc3\xa9 0";
  EXPECT_EQ(amc_error(amc), "t.amc:8: expected a number, found '\\xc3\\xa9'");
}

TEST(AsfAmcErrors, ManyBonesWithoutDofCannotBlowUpTheClip) {
  // 3000 bones without DOF stored at each of 2000 tiny frames would be 12M joint-frames (670 MB)
  // from a 59 kB AMC; the reader refuses while reading, before allocating the clip.
  std::vector<std::string> asf = mini_asf();
  asf.resize(22);
  std::string hierarchy = "    b";
  for (int k = 0; k < 3000; ++k) {
    const std::string name = "n" + std::to_string(k);
    asf.insert(asf.end(),
               {"  begin", "    name " + name, "    direction 0 1 0", "    length 1", "  end"});
    hierarchy += " " + name;
  }
  asf.insert(asf.end(), {":hierarchy", "  begin", "    root a", "    a b", hierarchy, "  end"});
  std::vector<std::string> amc;
  for (int f = 1; f <= 2000; ++f) {
    amc.insert(amc.end(), {std::to_string(f), "root 0 0 0 0 0 0", "a 0 0 0"});
  }
  const std::string error = message(parse_mini(asf, amc));
  // 3000 bones n0..n2999, each with an End Site, plus root, a, b: 6003 joints. The AMC is 58,893
  // bytes, so 4 * 58893 + 2^18 + 6003 = 503,719 joint-frames are allowed: 83 frames; frame 84
  // (line 250) is refused.
  EXPECT_EQ(error,
            "t.amc:250: the clip would hold more than 503719 joint-frames (6003 joints at every "
            "frame), too many for the file's size: bones without DOF?");
}

TEST(AsfAmcErrors, BadOptions) {
  AsfAmcReadOptions options;
  options.frame_rate = 0.0;
  EXPECT_EQ(amc_error(mini_amc(), options), "t.amc: frame rate must be positive and finite");
  options.frame_rate = 60.0;
  options.metres_per_unit = -1.0;
  EXPECT_EQ(amc_error(mini_amc(), options), "t.asf: metres per unit must be positive and finite");
}

// ----------------------------------------------------------------------------- real CMU data

class CmuSalsa : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!std::filesystem::exists(kCmu + "60.asf")) return;
    AsfAmcReadOptions options;
    options.frame_rate = 60.0;  // the salsa takes are 60 Hz (cmu-salsa/README.md)
    Result<Clip> asf = read_asf_amc(kCmu + "60.asf", kCmu + "60_01.amc", options);
    ASSERT_TRUE(asf) << asf.error().message;
    clip_ = new Clip(std::move(asf).value());
  }
  static void TearDownTestSuite() {
    delete clip_;
    clip_ = nullptr;
  }
  void SetUp() override {
    if (clip_ == nullptr) GTEST_SKIP() << "no CMU data in " << kCmu;
  }
  static Clip* clip_;
};
Clip* CmuSalsa::clip_ = nullptr;

TEST_F(CmuSalsa, Loads2242Frames) {
  const Clip& clip = *clip_;
  EXPECT_EQ(clip.frame_count(), 2242);
  EXPECT_EQ(clip.frame_rate(), 60.0);
  EXPECT_EQ(clip.skeleton().validate(), "");
  // root + 30 bones + End Sites at the tips of the 7 leaf bones.
  EXPECT_EQ(clip.joint_count(), 38);
  EXPECT_EQ(clip.skeleton().animated_joint_count(), 31);
  // lhipjoint has no DOF: identity at every frame; its child starts at the tip of the bone.
  const int lhip = clip.skeleton().find("lhipjoint");
  const int lfemur = clip.skeleton().find("lfemur");
  ASSERT_GE(lhip, 0);
  ASSERT_GE(lfemur, 0);
  for (int f = 0; f < clip.frame_count(); ++f) {
    ASSERT_LT(angle_deg(clip.rotations_ls(f)[static_cast<std::size_t>(lhip)], Quat::Identity()),
              1e-12);
  }
  EXPECT_TRUE(clip.skeleton().joints[static_cast<std::size_t>(lfemur)].offset.isApprox(
      Vec3(1.40252, -1.71424, 0.59123) * kCmuMetresPerUnit, 1e-5));
  // Root height 0.43-1.00 m (cmu-salsa/README.md).
  double low = 1e9, high = -1e9;
  for (int f = 0; f < clip.frame_count(); ++f) {
    low = std::min(low, clip.translations_ls(f)[0].y());
    high = std::max(high, clip.translations_ls(f)[0].y());
  }
  EXPECT_NEAR(low, 0.43, 0.01);
  EXPECT_NEAR(high, 1.00, 0.01);
}

// The crosscheck BVH (crosscheck/cmu_60_01.bvh) is an independent conversion of the same files.
// AMC frame k (1-based) is its frame k-1: it has 2242 frames and no added rest-pose frame.
// Its joints carry our local rotations exactly, but its hierarchy is shifted by one bone: joint
// X's OFFSET is bone X's own vector (so joint X sits at the *tip* of bone X) while joint X's
// channels still hold bone X's rotation, which in BVH only turns X's children. Read as a plain
// BVH, every bone is therefore turned by its parent's rotation (see
// CrosscheckAsPlainBvhIsOffByOne).
class CmuCrosscheck : public CmuSalsa {
 protected:
  void SetUp() override {
    CmuSalsa::SetUp();
    if (IsSkipped()) return;
    if (!std::filesystem::exists(kCrosscheck)) GTEST_SKIP() << "no " << kCrosscheck;
    BvhReadOptions options;
    options.scale = kCmuMetresPerUnit;  // the crosscheck is in CMU units
    Result<Clip> bvh = read_bvh(kCrosscheck, options);
    ASSERT_TRUE(bvh) << bvh.error().message;
    bvh_ = std::move(bvh).value();
    ASSERT_EQ(bvh_.frame_count(), clip_->frame_count());
  }
  Clip bvh_;
};

TEST_F(CmuCrosscheck, SameJointsAndLocalRotationsByName) {
  const Skeleton& ours = clip_->skeleton();
  const Skeleton& theirs = bvh_.skeleton();
  ASSERT_EQ(ours.joint_count(), theirs.joint_count());
  double worst_deg = 0.0, worst_root_mm = 0.0;
  for (int j = 0; j < theirs.joint_count(); ++j) {
    const Joint& joint = theirs.joints[static_cast<std::size_t>(j)];
    const int o = ours.find(joint.name);
    ASSERT_GE(o, 0) << joint.name;
    EXPECT_EQ(ours.joints[static_cast<std::size_t>(o)].channels, joint.channels) << joint.name;
    for (int f = 0; f < bvh_.frame_count(); ++f) {
      worst_deg = std::max(worst_deg, angle_deg(clip_->rotations_ls(f)[static_cast<std::size_t>(o)],
                                                bvh_.rotations_ls(f)[static_cast<std::size_t>(j)]));
    }
  }
  for (int f = 0; f < bvh_.frame_count(); ++f) {
    worst_root_mm = std::max(
        worst_root_mm, 1000.0 * (clip_->translations_ls(f)[0] - bvh_.translations_ls(f)[0]).norm());
  }
  RecordProperty("max_local_rotation_difference_deg", std::to_string(worst_deg));
  EXPECT_LT(worst_deg, 1e-4);  // the BVH prints 6 decimals of degrees
  EXPECT_LT(worst_root_mm, 1e-3);
}

TEST_F(CmuCrosscheck, ForwardKinematicsMatchesWithin1mmOnEveryFrame) {
  // The crosscheck's joint X is at the tip of bone X. Its positions are computed with each
  // joint's own rotation applied to its own OFFSET (undoing the one-bone shift) and compared with
  // our joint at the tip of bone X: X's first child, or X_End. Root and End Sites keep their names.
  const Skeleton& ours = clip_->skeleton();
  const Skeleton& theirs = bvh_.skeleton();
  const auto n_ours = static_cast<std::size_t>(ours.joint_count());
  const auto n = static_cast<std::size_t>(theirs.joint_count());
  std::vector<std::size_t> tip_of(n);
  for (std::size_t j = 0; j < n; ++j) {
    const Joint& joint = theirs.joints[j];
    const int o = ours.find(joint.name);
    ASSERT_GE(o, 0) << joint.name;
    tip_of[j] = static_cast<std::size_t>(o);
    if (o == 0 || joint.end_site) continue;
    const auto child = std::find_if(ours.joints.begin(), ours.joints.end(),
                                    [&](const Joint& c) { return c.parent == o; });
    ASSERT_NE(child, ours.joints.end()) << joint.name;
    tip_of[j] = static_cast<std::size_t>(child - ours.joints.begin());
  }
  const std::vector<Vec3> positions = world_positions(*clip_);
  std::vector<Vec3> theirs_ws(n), plain_ws(n);
  std::vector<Quat> rotations_ws(n);
  double worst_mm = 0.0;
  int worst_frame = -1;
  std::string worst_joint;
  for (int f = 0; f < bvh_.frame_count(); ++f) {
    const auto t = bvh_.translations_ls(f);
    forward_kinematics(theirs, t, bvh_.rotations_ls(f), plain_ws, rotations_ws);
    for (std::size_t j = 0; j < n; ++j) {
      const int parent = theirs.joints[j].parent;
      theirs_ws[j] =
          parent < 0 ? t[j]
                     : Vec3(theirs_ws[static_cast<std::size_t>(parent)] + rotations_ws[j] * t[j]);
      const double mm =
          1000.0 *
          (theirs_ws[j] - positions[static_cast<std::size_t>(f) * n_ours + tip_of[j]]).norm();
      if (mm > worst_mm) {
        worst_mm = mm;
        worst_frame = f;
        worst_joint = theirs.joints[j].name;
      }
    }
  }
  RecordProperty("max_position_error_mm", std::to_string(worst_mm));
  EXPECT_LT(worst_mm, 1.0) << "at " << worst_joint << ", frame " << worst_frame;
}

TEST_F(CmuCrosscheck, CrosscheckAsPlainBvhIsOffByOne) {
  // Read literally, the crosscheck's knee ("lfemur", the tip of the femur) is rigid in the pelvis
  // frame, because lhipjoint has no DOF and lfemur's own rotation only turns the shin. Ours moves
  // with the thigh, as a dancer's knee does. This is why the test above undoes the shift.
  const Skeleton& theirs = bvh_.skeleton();
  const auto n = static_cast<std::size_t>(theirs.joint_count());
  const auto n_ours = static_cast<std::size_t>(clip_->joint_count());
  const auto knee_theirs = static_cast<std::size_t>(theirs.find("lfemur"));
  const auto knee_ours = static_cast<std::size_t>(clip_->skeleton().find("ltibia"));
  const std::vector<Vec3> theirs_ws = world_positions(bvh_);
  const std::vector<Vec3> ours_ws = world_positions(*clip_);
  Eigen::AlignedBox3d theirs_box, ours_box;
  for (int f = 0; f < bvh_.frame_count(); ++f) {
    const auto i = static_cast<std::size_t>(f);
    const Quat pelvis_theirs = bvh_.rotations_ls(f)[0];
    const Quat pelvis_ours = clip_->rotations_ls(f)[0];
    theirs_box.extend(pelvis_theirs.conjugate() *
                      (theirs_ws[i * n + knee_theirs] - theirs_ws[i * n]));
    ours_box.extend(pelvis_ours.conjugate() *
                    (ours_ws[i * n_ours + knee_ours] - ours_ws[i * n_ours]));
  }
  EXPECT_LT(theirs_box.diagonal().norm(), 1e-6);
  EXPECT_GT(ours_box.diagonal().norm(), 0.3);
}

}  // namespace
}  // namespace duet
