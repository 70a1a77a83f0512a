// BVH writer: exact output for a tiny clip, read-write-read round trips of the fixtures, units,
// and write_bvh's no-half-written-file guarantee.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "duet/io/bvh.h"
#include "duet/math/rotation.h"
#include "duet/motion/forward_kinematics.h"

namespace duet {
namespace {

namespace fs = std::filesystem;

const std::string kFixtures = std::string(DUET_TESTDATA_DIR) + "/bvh/";

Clip must_parse(const std::string& text) {
  Result<Clip> clip = parse_bvh(text, "round-trip.bvh");
  EXPECT_TRUE(clip.ok()) << (clip.ok() ? "" : clip.error().message) << "\n" << text;
  return clip.ok() ? std::move(clip).value() : Clip();
}

Clip must_read(const std::string& path) {
  Result<Clip> clip = read_bvh(path);
  EXPECT_TRUE(clip.ok()) << (clip.ok() ? "" : clip.error().message);
  return clip.ok() ? std::move(clip).value() : Clip();
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A fresh directory under the system temp dir, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() /
            ("duet_bvh_writer_test_" +
             std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

void expect_same_clip(const Clip& a, const Clip& b, double length_tolerance) {
  ASSERT_EQ(a.joint_count(), b.joint_count());
  ASSERT_EQ(a.frame_count(), b.frame_count());
  EXPECT_NEAR(a.frame_rate(), b.frame_rate(), 1e-9 * a.frame_rate());
  for (int j = 0; j < a.joint_count(); ++j) {
    const Joint& ja = a.skeleton().joints[static_cast<std::size_t>(j)];
    const Joint& jb = b.skeleton().joints[static_cast<std::size_t>(j)];
    EXPECT_EQ(ja.name, jb.name);
    EXPECT_EQ(ja.parent, jb.parent);
    EXPECT_EQ(ja.end_site, jb.end_site);
    EXPECT_EQ(ja.channels, jb.channels) << ja.name;
    EXPECT_LT((ja.offset - jb.offset).norm(), length_tolerance) << ja.name;
  }
  for (int f = 0; f < a.frame_count(); ++f) {
    for (int j = 0; j < a.joint_count(); ++j) {
      const auto k = static_cast<std::size_t>(j);
      EXPECT_LT((a.translations_ls(f)[k] - b.translations_ls(f)[k]).norm(), length_tolerance);
      EXPECT_GT(std::abs(a.rotations_ls(f)[k].dot(b.rotations_ls(f)[k])), 1.0 - 1e-12)
          << "frame " << f << " joint " << j;
    }
  }
}

TEST(BvhWriter, ExactOutputForATinyClip) {
  auto skeleton = std::make_shared<Skeleton>();
  Joint root;
  root.name = "hip";
  root.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition,
                   Channel::kZrotation, Channel::kYrotation, Channel::kXrotation};
  Joint knee;
  knee.name = "knee";
  knee.parent = 0;
  knee.offset = {0, -0.5, 0.25};
  knee.channels = {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
  Joint tip;
  tip.name = "knee_End";
  tip.parent = 1;
  tip.offset = {0, -0.5, 0};
  tip.end_site = true;
  skeleton->joints = {root, knee, tip};
  Clip clip(skeleton, 60.0, 2);
  clip.translations_ls(0)[0] = {1, 2, 3};
  clip.rotations_ls(0)[1] = Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitX()));
  clip.translations_ls(1)[0] = {-1, 0.5, -1e-9};
  clip.rotations_ls(1)[0] = Quat(Eigen::AngleAxisd(-kPi / 6, Vec3::UnitZ()));

  BvhWriteOptions options;
  options.units_per_metre = 100.0;
  options.decimals = 2;
  EXPECT_EQ(format_bvh(clip, options),
            "HIERARCHY\n"
            "ROOT hip\n"
            "{\n"
            "\tOFFSET 0.00 0.00 0.00\n"
            "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"
            "\tJOINT knee\n"
            "\t{\n"
            "\t\tOFFSET 0.00 -50.00 25.00\n"
            "\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n"
            "\t\tEnd Site\n"
            "\t\t{\n"
            "\t\t\tOFFSET 0.00 -50.00 0.00\n"
            "\t\t}\n"
            "\t}\n"
            "}\n"
            "MOTION\n"
            "Frames: 2\n"
            "Frame Time: 0.016666666666666666\n"
            "100.00 200.00 300.00 0.00 0.00 0.00 0.00 90.00 0.00\n"
            "-100.00 50.00 0.00 -30.00 0.00 0.00 0.00 0.00 0.00\n");
}

TEST(BvhWriter, RoundTripOfEveryFixtureKeepsSkeletonAndValues) {
  for (const auto& entry : fs::directory_iterator(kFixtures)) {
    if (entry.path().extension() != ".bvh") continue;
    SCOPED_TRACE(entry.path().string());
    const Clip original = must_read(entry.path().string());
    const Clip again = must_parse(format_bvh(original));
    expect_same_clip(original, again, 1e-6);
    // And the text is a fixed point: writing the re-read clip gives the same bytes.
    EXPECT_EQ(format_bvh(again), format_bvh(original));
  }
}

TEST(BvhWriter, UnitsPerMetreScalesOffsetsAndPositionChannels) {
  const Clip clip = must_read(kFixtures + "six_channel_joint.bvh");
  BvhWriteOptions options;
  options.units_per_metre = 100.0;
  BvhReadOptions read_options;
  read_options.scale = 0.01;
  Result<Clip> again = parse_bvh(format_bvh(clip, options), "cm.bvh", read_options);
  ASSERT_TRUE(again.ok()) << again.error().message;
  expect_same_clip(clip, again.value(), 1e-7);
  EXPECT_NE(format_bvh(clip, options).find("OFFSET 0.000000 90.000000 0.000000"),
            std::string::npos);
}

TEST(BvhWriter, RotationsNearGimbalLockRoundTrip) {
  const Clip base = must_read(kFixtures + "order_zxy.bvh");
  Clip clip(base.skeleton_ptr(), 30.0, 4);
  const double angles[4] = {kPi / 2, -kPi / 2, kPi / 2 - 1e-7, kPi};
  for (int f = 0; f < 4; ++f) {
    // About the middle axis of the joint's order: the Euler decomposition is degenerate there.
    clip.rotations_ls(f)[0] = Quat(Eigen::AngleAxisd(angles[f], Vec3::UnitX())) *
                              Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
    clip.rotations_ls(f)[1] = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  }
  BvhWriteOptions options;
  options.decimals = 12;
  const Clip again = must_parse(format_bvh(clip, options));
  ASSERT_EQ(again.frame_count(), 4);
  for (int f = 0; f < 4; ++f) {
    for (std::size_t j = 0; j < 2; ++j) {
      EXPECT_GT(std::abs(clip.rotations_ls(f)[j].dot(again.rotations_ls(f)[j])), 1.0 - 1e-12)
          << "frame " << f << " joint " << j;
    }
  }
}

// The writer's angles come from euler_from_quat. Close to gimbal lock it used to solve the first
// and third angles independently from matrix entries that shrink with cos(middle angle), losing
// about 3e-16 / cos(middle) radians: 3e-6 rad at 1e-10 from lock, 3e-4 rad at 1e-12.
TEST(BvhWriter, EulerAnglesNearGimbalLockAreAccurateToRounding) {
  std::uint32_t seed = 12345;
  auto uniform = [&seed] {  // small LCG: deterministic and independent of the platform
    seed = seed * 1664525u + 1013904223u;
    return (seed >> 8) / double(1u << 24) * 2.0 * kPi - kPi;
  };
  for (const char* name : {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"}) {
    EulerOrder order{};
    ASSERT_TRUE(parse_euler_order(name, order));
    for (const double eps : {1e-2, 1e-4, 1e-6, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 0.0}) {
      double worst = 0.0;
      for (int trial = 0; trial < 200; ++trial) {
        const double middle = (trial % 2 ? 1.0 : -1.0) * (kPi / 2 - eps);
        const Quat q = quat_from_euler(Vec3(uniform(), middle, uniform()), order);
        const Quat back = quat_from_euler(euler_from_quat(q, order), order);
        worst = std::max(worst, std::min((q.coeffs() - back.coeffs()).norm(),
                                         (q.coeffs() + back.coeffs()).norm()));
      }
      EXPECT_LT(worst, 2e-12) << name << ", " << eps << " rad from gimbal lock";
    }
  }
}

TEST(BvhWriter, ZeroFrameClip) {
  const Clip clip = must_read(kFixtures + "order_xyz.bvh");
  const Clip empty(clip.skeleton_ptr(), 24.0, 0);
  const Clip again = must_parse(format_bvh(empty));
  EXPECT_EQ(again.frame_count(), 0);
  EXPECT_EQ(again.joint_count(), clip.joint_count());
  EXPECT_DOUBLE_EQ(again.frame_rate(), 24.0);
}

TEST(BvhWriter, WriteBvhWritesTheFileAndLeavesNoTemporary) {
  TempDir dir;
  const Clip clip = must_read(kFixtures + "six_channel_joint.bvh");
  const std::string path = dir.file("out.bvh");
  const Status status = write_bvh(clip, path);
  ASSERT_TRUE(status.ok()) << status.error().message;
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  EXPECT_EQ(slurp(path), format_bvh(clip));
  expect_same_clip(clip, must_read(path), 1e-6);
}

TEST(BvhWriter, WriteBvhReplacesAnExistingFileWhole) {
  TempDir dir;
  const std::string path = dir.file("out.bvh");
  std::ofstream(path) << "old contents that are longer than nothing at all";
  const Clip clip = must_read(kFixtures + "order_xyz.bvh");
  ASSERT_TRUE(write_bvh(clip, path).ok());
  EXPECT_EQ(slurp(path), format_bvh(clip));
}

TEST(BvhWriter, WriteFailureNamesThePathAndLeavesNothingBehind) {
  TempDir dir;
  const Clip clip = must_read(kFixtures + "order_xyz.bvh");
  // A directory that does not exist: the temporary file cannot be created.
  const std::string missing = dir.file("no/such/dir/out.bvh");
  Status status = write_bvh(clip, missing);
  ASSERT_FALSE(status.ok());
  EXPECT_TRUE(status.error().message.starts_with(missing + ": ")) << status.error().message;
  EXPECT_FALSE(fs::exists(missing + ".tmp"));
  // The target is a non-empty directory: writing the temporary works, the rename fails, and the
  // temporary must be removed.
  const std::string blocked = dir.file("blocked.bvh");
  fs::create_directories(blocked + "/child");
  status = write_bvh(clip, blocked);
  ASSERT_FALSE(status.ok());
  EXPECT_TRUE(status.error().message.starts_with(blocked + ": ")) << status.error().message;
  EXPECT_FALSE(fs::exists(blocked + ".tmp"));
  EXPECT_TRUE(fs::is_directory(blocked));
}

TEST(BvhWriter, WriteBvhRejectsClipsItCannotWrite) {
  TempDir dir;
  const std::string path = dir.file("bad.bvh");
  Status status = write_bvh(Clip(), path);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message, path + ": cannot write: clip has no skeleton");
  Clip clip = must_read(kFixtures + "order_xyz.bvh");
  clip.set_frame_rate(0.0);
  status = write_bvh(clip, path);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message,
            path + ": cannot write: frame rate must be positive and finite");
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace duet
