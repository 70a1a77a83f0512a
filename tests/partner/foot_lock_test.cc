// Foot locking: a foot that slides slowly near the ground slides much less; a lifted or fast foot
// is left alone; releasing a lock never pops; the root shift stays bounded.
#include "duet/partner/foot_lock.h"

#include <gtest/gtest.h>

#include <cmath>

namespace duet {
namespace {

constexpr double kDt = 1.0 / 60;
const std::array<double, 2> kGround = {0.05, 0.04};

// The right foot hangs in the air; the left one follows `left(t)`.
template <typename Path>
double shown_travel(FootLocker& locker, const FootLockParams& params, Path left, int frames,
                    double* largest_offset = nullptr) {
  Vec3 first = Vec3::Zero(), last = Vec3::Zero();
  for (int i = 0; i < frames; ++i) {
    const std::array<Vec3, 2> feet = {left(i * kDt), Vec3(0.3, 0.5, 0.0)};
    const Vec3 offset = locker.update(feet, kGround, params, kDt);
    EXPECT_EQ(offset.y(), 0.0);
    if (largest_offset) *largest_offset = std::max(*largest_offset, offset.norm());
    const Vec3 shown = feet[0] + offset;
    if (i == 0) first = shown;
    last = shown;
  }
  return (last - first).norm();
}

TEST(FootLocker, ASlidingFootNearTheGroundSlidesMuchLess) {
  const FootLockParams params;
  const auto sliding = [](double t) { return Vec3(0.1 * t, 0.06, 0.05 * t); };  // 0.11 m/s
  FootLocker locker;
  const double travel = shown_travel(locker, params, sliding, 60);  // 1 s: 0.11 m raw
  EXPECT_LT(travel, 0.01);
  EXPECT_TRUE(locker.locked(0));
  EXPECT_FALSE(locker.locked(1));
}

TEST(FootLocker, LiftedOrFastFeetAreNotLocked) {
  const FootLockParams params;
  FootLocker lifted;
  const double up = shown_travel(
      lifted, params, [](double t) { return Vec3(0.1 * t, 0.2, 0); }, 60);
  EXPECT_NEAR(up, 0.1 * 59 * kDt, 1e-12);
  EXPECT_FALSE(lifted.locked(0));
  FootLocker fast;
  const double run = shown_travel(
      fast, params, [](double t) { return Vec3(1.0 * t, 0.05, 0); }, 60);
  EXPECT_NEAR(run, 59 * kDt, 1e-12);
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
    const Vec3 offset = locker.update({foot, Vec3(0, 0.5, 0)}, kGround, params, kDt);
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
    locker.update({Vec3(0.1 * t, 0.05, 0), Vec3(0.3 + 0.1 * t, 0.04, 0)}, kGround, params, kDt);
  }
  EXPECT_TRUE(locker.locked(0));
  EXPECT_TRUE(locker.locked(1));
  EXPECT_NEAR(locker.offset().x(), -0.1 * 28 * kDt, 1e-9);  // locked from the second frame
  locker.reset();
  EXPECT_FALSE(locker.locked(0));
  EXPECT_EQ(locker.offset(), Vec3::Zero());
}

TEST(FootLocker, NonFiniteInputGivesAFiniteShift) {
  const FootLockParams params;
  FootLocker locker;
  locker.update({Vec3(0, 0.05, 0), Vec3(0, 0.05, 0)}, kGround, params, kDt);
  const Vec3 bad(std::nan(""), 0.05, 0);
  const Vec3 offset = locker.update({bad, Vec3(0, 0.05, 0)}, kGround, params, kDt);
  EXPECT_TRUE(offset.allFinite());
  EXPECT_TRUE(
      locker.update({Vec3(0, 0.05, 0), Vec3(0, 0.05, 0)}, kGround, params, kDt).allFinite());
}

}  // namespace
}  // namespace duet
