// Foot locking: a planted foot that slides slowly slides much less, also when the pose jitters
// like a noisy sensor's; a foot that is not planted is left alone; releasing a lock never pops;
// the root shift stays bounded.
#include "duet/partner/foot_lock.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace duet {
namespace {

constexpr double kDt = 1.0 / 60;
constexpr std::array<bool, 2> kLeftPlanted = {true, false};

// The right foot hangs in the air; the left one follows `left(t)`, planted or not.
template <typename Path>
double shown_travel(FootLocker& locker, const FootLockParams& params, Path left, int frames,
                    double* largest_offset = nullptr, bool planted = true) {
  Vec3 first = Vec3::Zero(), last = Vec3::Zero();
  for (int i = 0; i < frames; ++i) {
    const std::array<Vec3, 2> feet = {left(i * kDt), Vec3(0.3, 0.5, 0.0)};
    const Vec3 offset = locker.update(feet, {planted, false}, params, kDt);
    EXPECT_EQ(offset.y(), 0.0);
    if (largest_offset) *largest_offset = std::max(*largest_offset, offset.norm());
    const Vec3 shown = feet[0] + offset;
    if (i == 0) first = shown;
    last = shown;
  }
  return (last - first).norm();
}

TEST(FootLocker, APlantedSlidingFootSlidesMuchLess) {
  const FootLockParams params;
  const auto sliding = [](double t) { return Vec3(0.1 * t, 0.06, 0.05 * t); };  // 0.11 m/s
  FootLocker locker;
  const double travel = shown_travel(locker, params, sliding, 60);  // 1 s: 0.11 m raw
  EXPECT_LT(travel, 0.01);
  EXPECT_TRUE(locker.locked(0));
  EXPECT_FALSE(locker.locked(1));
}

TEST(FootLocker, FeetThatAreNotPlantedAreLeftAlone) {
  const FootLockParams params;
  FootLocker locker;
  const double travel = shown_travel(
      locker, params, [](double t) { return Vec3(0.1 * t, 0.2, 0); }, 60, nullptr, false);
  EXPECT_NEAR(travel, 0.1 * 59 * kDt, 1e-12);
  EXPECT_FALSE(locker.locked(0));
  EXPECT_EQ(locker.offset(), Vec3::Zero());
}

TEST(FootLocker, APlantedFootStaysPutUnderSensorJitter) {
  // The whole pose jitters by 1 cm per axis per frame (a partner placed relative to a noisy
  // user root): its toe moves at about 1 m/s, five times any plant speed threshold. Planted per
  // the captured motion, it stays put.
  const FootLockParams params;
  std::mt19937 rng(3);
  std::normal_distribution<double> jitter(0.0, 0.01);
  FootLocker locker;
  Vec3 previous = Vec3::Zero();
  double raw_path = 0.0, shown_path = 0.0;
  Vec3 previous_raw = Vec3::Zero();
  for (int i = 0; i < 120; ++i) {
    const Vec3 raw(jitter(rng), 0.05, jitter(rng));
    const Vec3 shown = raw + locker.update({raw, Vec3(0.3, 0.5, 0.0)}, kLeftPlanted, params, kDt);
    if (i > 0) {
      raw_path += (raw - previous_raw).norm();
      shown_path += (shown - previous).norm();
    }
    previous = shown;
    previous_raw = raw;
  }
  EXPECT_GT(raw_path, 1.5);  // about 1.9 m of jitter in 2 s
  EXPECT_LT(shown_path, 1e-9);
  EXPECT_TRUE(locker.locked(0));
}

TEST(FootLocker, ShiftStaysWithinTheLimit) {
  FootLockParams params;
  params.max_offset_m = 0.05;
  FootLocker locker;
  double largest = 0.0;
  // 0.15 m/s for 4 s: 0.6 m of raw slide; the root may move at most 5 cm (plus one frame).
  shown_travel(
      locker, params, [](double t) { return Vec3(0.15 * t, 0.05, 0); }, 240, &largest);
  EXPECT_LE(largest, 0.05 + 0.15 * kDt + 1e-12);
}

TEST(FootLocker, ReleaseDoesNotPop) {
  const FootLockParams params;
  FootLocker locker;
  Vec3 previous_shown = Vec3::Zero();
  double largest_step = 0.0;
  for (int i = 0; i < 180; ++i) {
    const double t = i * kDt;
    // Slides slowly on the ground for 1 s, then lifts and stays still in the air.
    const Vec3 foot = t < 1.0 ? Vec3(0.15 * t, 0.05, 0) : Vec3(0.15, 0.3, 0);
    const Vec3 offset = locker.update({foot, Vec3(0, 0.5, 0)}, {t < 1.0, false}, params, kDt);
    const Vec3 shown = foot + offset;
    const Vec3 step = shown - previous_shown;
    if (i > 0) largest_step = std::max(largest_step, std::hypot(step.x(), step.z()));
    previous_shown = shown;
  }
  EXPECT_FALSE(locker.locked(0));
  // The raw foot moves 2.5 mm per frame; the release decays the shift without a jump.
  EXPECT_LT(largest_step, 0.02);
  EXPECT_LT(locker.offset().norm(), 1e-3);  // 2 s after release: decayed
}

TEST(FootLocker, TwoLockedFeetShareTheShiftAndResetForgets) {
  const FootLockParams params;
  FootLocker locker;
  for (int i = 0; i < 30; ++i) {
    const double t = i * kDt;
    // Both feet on the ground, the body drifting at 0.1 m/s: both stay put.
    locker.update({Vec3(0.1 * t, 0.05, 0), Vec3(0.3 + 0.1 * t, 0.04, 0)}, {true, true}, params,
                  kDt);
  }
  EXPECT_TRUE(locker.locked(0));
  EXPECT_TRUE(locker.locked(1));
  EXPECT_NEAR(locker.offset().x(), -0.1 * 29 * kDt, 1e-9);  // locked from the first frame
  locker.reset();
  EXPECT_FALSE(locker.locked(0));
  EXPECT_EQ(locker.offset(), Vec3::Zero());
}

TEST(FootLocker, NonFiniteInputGivesAFiniteShift) {
  const FootLockParams params;
  FootLocker locker;
  constexpr std::array<bool, 2> kBoth = {true, true};
  locker.update({Vec3(0, 0.05, 0), Vec3(0, 0.05, 0)}, kBoth, params, kDt);
  const Vec3 bad(std::nan(""), 0.05, 0);
  const Vec3 offset = locker.update({bad, Vec3(0, 0.05, 0)}, kBoth, params, kDt);
  EXPECT_TRUE(offset.allFinite());
  EXPECT_TRUE(locker.update({Vec3(0, 0.05, 0), Vec3(0, 0.05, 0)}, kBoth, params, kDt).allFinite());
}

}  // namespace
}  // namespace duet
