// BVH reader and writer on the real CMU data (DUET_DATA_DIR, see /work/shared/data/README.md):
// frame counts from the data README, the handshake files' other convention, a metric write-read
// round trip checked through forward kinematics, and the salsa pairs' synchronisation.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "duet/io/bvh.h"
#include "duet/motion/forward_kinematics.h"

namespace duet {
namespace {

const std::string kData = DUET_DATA_DIR;
const std::string kSalsa = kData + "/cmu-salsa/bvh/";
constexpr double kSalsaMetresPerUnit = 1.0 / 0.768;  // data README: about 0.768 units per metre

struct Trial {
  const char* id;
  int frames;
};
// Frame counts from the table in cmu-salsa/README.md (identical for 60 and 61).
constexpr std::array<Trial, 14> kTrials = {{{"01", 2242},
                                            {"02", 2101},
                                            {"03", 1830},
                                            {"04", 1871},
                                            {"05", 1678},
                                            {"06", 1772},
                                            {"07", 2071},
                                            {"09", 2575},
                                            {"10", 1197},
                                            {"11", 2108},
                                            {"12", 1690},
                                            {"13", 2271},
                                            {"14", 1949},
                                            {"15", 2140}}};

std::string salsa_path(int subject, const char* trial) {
  return kSalsa + std::to_string(subject) + "/" + std::to_string(subject) + "_" + trial +
         "_scaled.bvh";
}

#define SKIP_WITHOUT_DATA()                                                            \
  if (!std::filesystem::exists(kSalsa)) GTEST_SKIP() << "no motion data at " << kData; \
  static_assert(true)

Clip must_read(const std::string& path, const BvhReadOptions& options = {}) {
  Result<Clip> clip = read_bvh(path, options);
  EXPECT_TRUE(clip.ok()) << (clip.ok() ? "" : clip.error().message);
  return clip.ok() ? std::move(clip).value() : Clip();
}

TEST(BvhData, EverySalsaFileLoadsWithTheReadmeFrameCount) {
  SKIP_WITHOUT_DATA();
  for (const int subject : {60, 61}) {
    for (const Trial& trial : kTrials) {
      const std::string path = salsa_path(subject, trial.id);
      SCOPED_TRACE(path);
      const Clip clip = must_read(path);
      EXPECT_EQ(clip.frame_count(), trial.frames);
      EXPECT_EQ(clip.skeleton().animated_joint_count(), 43);
      EXPECT_EQ(clip.skeleton().channel_count(), 132);
      EXPECT_NEAR(clip.frame_rate(), 1.0 / 0.008333, 1e-9);  // the header's (wrong) 120 fps
      const Joint& hip = clip.skeleton().joints[0];
      EXPECT_EQ(hip.name, "hip");
      EXPECT_EQ(hip.rotation_order(), (EulerOrder{Axis::kZ, Axis::kY, Axis::kX}));
      const Joint& abdomen = clip.skeleton().joints[1];
      EXPECT_EQ(abdomen.rotation_order(), (EulerOrder{Axis::kZ, Axis::kX, Axis::kY}));
      EXPECT_GE(clip.skeleton().find("lFoot_End"), 0);
    }
  }
}

TEST(BvhData, FrameRateOverrideAndMetricScale) {
  SKIP_WITHOUT_DATA();
  BvhReadOptions options;
  options.frame_rate = 60.0;
  options.scale = kSalsaMetresPerUnit;
  const Clip clip = must_read(salsa_path(60, "01"), options);
  EXPECT_DOUBLE_EQ(clip.frame_rate(), 60.0);
  EXPECT_NEAR(clip.duration(), 37.37, 0.01);  // MANIFEST.tsv: duration_s_if_60fps
  // README: standing hip height about 0.66 units; head joint about 1.14 units.
  const std::vector<Vec3> world = world_positions(clip);
  const int head = clip.skeleton().find("head");
  std::vector<double> hip_heights, head_heights;
  for (int f = 0; f < clip.frame_count(); ++f) {
    const auto base = static_cast<std::size_t>(f * clip.joint_count());
    hip_heights.push_back(world[base].y());
    head_heights.push_back(world[base + static_cast<std::size_t>(head)].y());
  }
  std::nth_element(hip_heights.begin(), hip_heights.begin() + hip_heights.size() / 2,
                   hip_heights.end());
  std::nth_element(head_heights.begin(), head_heights.begin() + head_heights.size() / 2,
                   head_heights.end());
  EXPECT_NEAR(hip_heights[hip_heights.size() / 2], 0.66 * kSalsaMetresPerUnit, 0.08);
  EXPECT_NEAR(head_heights[head_heights.size() / 2], 1.14 * kSalsaMetresPerUnit, 0.1);
}

TEST(BvhData, HandshakeFilesLoadInTheirOwnConvention) {
  SKIP_WITHOUT_DATA();
  for (const char* name : {"18_01.bvh", "19_01.bvh"}) {
    const std::string path = kData + "/cmu-handshake/" + name;
    SCOPED_TRACE(path);
    const Clip clip = must_read(path);
    EXPECT_EQ(clip.frame_count(), 304);
    EXPECT_EQ(clip.skeleton().animated_joint_count(), 31);
    EXPECT_EQ(clip.skeleton().joints[0].name, "Hips");
    EXPECT_EQ(clip.skeleton().joints[1].name, "LHipJoint");
    EXPECT_EQ(clip.skeleton().joints[1].rotation_order(),
              (EulerOrder{Axis::kZ, Axis::kY, Axis::kX}));
    EXPECT_NEAR(clip.frame_rate(), 1.0 / 0.0083333, 1e-9);  // header ".0083333"
  }
}

TEST(BvhData, CrosscheckConversionLoads) {
  SKIP_WITHOUT_DATA();
  const Clip clip = must_read(kData + "/crosscheck/cmu_60_01.bvh");
  EXPECT_EQ(clip.frame_count(), 2242);
  EXPECT_NEAR(clip.frame_rate(), 60.0, 0.01);
}

// Write in metres, read back, compare world positions on every frame and joint.
void expect_round_trip_keeps_world_positions(const std::string& path, double metres_per_unit) {
  BvhReadOptions options;
  options.scale = metres_per_unit;
  options.frame_rate = 60.0;
  const Clip original = must_read(path, options);
  ASSERT_GT(original.frame_count(), 0);
  const std::string text = format_bvh(original);  // metres, 6 decimals
  Result<Clip> again = parse_bvh(text, path + " (rewritten)");
  ASSERT_TRUE(again.ok()) << again.error().message;
  ASSERT_EQ(again.value().frame_count(), original.frame_count());
  ASSERT_EQ(again.value().joint_count(), original.joint_count());
  EXPECT_NEAR(again.value().frame_rate(), 60.0, 1e-9);
  const std::vector<Vec3> a = world_positions(original);
  const std::vector<Vec3> b = world_positions(again.value());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, (a[i] - b[i]).norm());
  EXPECT_LT(worst, 1e-4) << "largest world-position difference, metres";
  std::printf("[ info ] %s: round trip max world-position error %.3g m over %zu joint-frames\n",
              path.c_str(), worst, a.size());
}

TEST(BvhData, WriteThenReadKeepsWorldPositionsWithinATenthOfAMillimetre) {
  SKIP_WITHOUT_DATA();
  expect_round_trip_keeps_world_positions(salsa_path(60, "01"), kSalsaMetresPerUnit);
  expect_round_trip_keeps_world_positions(salsa_path(61, "11"), kSalsaMetresPerUnit);
  expect_round_trip_keeps_world_positions(kData + "/cmu-handshake/18_01.bvh", 0.056444);
}

// ---- Synchronisation of the salsa pairs ------------------------------------------------------

// World positions (float, frame-major) of the hand joints: lHand, rHand and everything under
// them (finger joints and their End Sites).
struct HandTrack {
  int frames = 0;
  int joints = 0;
  std::vector<float> xyz;  // (frame * joints + joint) * 3
};

HandTrack hand_track(const Clip& clip) {
  const Skeleton& s = clip.skeleton();
  std::vector<bool> is_hand(static_cast<std::size_t>(s.joint_count()), false);
  for (int j = 0; j < s.joint_count(); ++j) {
    const Joint& joint = s.joints[static_cast<std::size_t>(j)];
    is_hand[static_cast<std::size_t>(j)] =
        joint.name == "lHand" || joint.name == "rHand" ||
        (joint.parent >= 0 && is_hand[static_cast<std::size_t>(joint.parent)]);
  }
  std::vector<int> hands;
  for (int j = 0; j < s.joint_count(); ++j) {
    if (is_hand[static_cast<std::size_t>(j)]) hands.push_back(j);
  }
  const std::vector<Vec3> world = world_positions(clip);
  HandTrack track;
  track.frames = clip.frame_count();
  track.joints = static_cast<int>(hands.size());
  for (int f = 0; f < track.frames; ++f) {
    for (const int j : hands) {
      const Vec3& p = world[static_cast<std::size_t>(f * s.joint_count() + j)];
      for (int k = 0; k < 3; ++k) track.xyz.push_back(static_cast<float>(p[k]));
    }
  }
  return track;
}

// Median over frames of the smallest distance between any hand joint of `a` at frame f and any
// of `b` at frame f + lag.
double median_min_hand_distance(const HandTrack& a, const HandTrack& b, int lag) {
  std::vector<float> minima;
  const int begin = std::max(0, -lag);
  const int end = std::min(a.frames, b.frames - lag);
  for (int f = begin; f < end; ++f) {
    const float* pa = &a.xyz[static_cast<std::size_t>(f * a.joints * 3)];
    const float* pb = &b.xyz[static_cast<std::size_t>((f + lag) * b.joints * 3)];
    float best = std::numeric_limits<float>::max();
    for (int i = 0; i < a.joints; ++i) {
      for (int j = 0; j < b.joints; ++j) {
        const float dx = pa[3 * i] - pb[3 * j];
        const float dy = pa[3 * i + 1] - pb[3 * j + 1];
        const float dz = pa[3 * i + 2] - pb[3 * j + 2];
        best = std::min(best, dx * dx + dy * dy + dz * dz);
      }
    }
    minima.push_back(best);
  }
  auto middle = minima.begin() + static_cast<std::ptrdiff_t>(minima.size() / 2);
  std::nth_element(minima.begin(), middle, minima.end());
  return std::sqrt(static_cast<double>(*middle));
}

// The data README says frame i of 60_NN goes with frame i of 61_NN: the hands are closest at lag
// 0 (within +-8 frames) in all 14 pairs. Lags -120..120 in steps of 4.
TEST(BvhData, SalsaPairsHaveTheirHandsClosestAtLagZero) {
  SKIP_WITHOUT_DATA();
  for (const Trial& trial : kTrials) {
    const Clip leader = must_read(salsa_path(60, trial.id));
    const Clip follower = must_read(salsa_path(61, trial.id));
    ASSERT_EQ(leader.frame_count(), follower.frame_count());
    const HandTrack a = hand_track(leader);
    const HandTrack b = hand_track(follower);
    ASSERT_EQ(a.joints, 32);  // 2 x (hand + 10 finger joints + 5 End Sites)
    int best_lag = 0;
    double best = std::numeric_limits<double>::max();
    double at_zero = 0.0;
    double at_120 = 0.0;
    for (int lag = -120; lag <= 120; lag += 4) {
      const double d = median_min_hand_distance(a, b, lag);
      if (d < best) {
        best = d;
        best_lag = lag;
      }
      if (lag == 0) at_zero = d;
      if (lag == -120 || lag == 120) at_120 = std::max(at_120, d);
    }
    std::printf(
        "[ info ] pair %s: best lag %+d (median min hand gap %.3f units), lag 0: %.3f, "
        "worse of +-120: %.3f (x%.2f)\n",
        trial.id, best_lag, best, at_zero, at_120, at_120 / at_zero);
    EXPECT_LE(std::abs(best_lag), 8) << "pair " << trial.id;
  }
}

}  // namespace
}  // namespace duet
