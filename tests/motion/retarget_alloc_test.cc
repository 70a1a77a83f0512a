// Retargeter::retarget_frame allocates nothing after set-up (the per-frame path of a live
// avatar). This file replaces the global operator new of the motion test program with a counting
// one (counting_new.h); counting is on only inside the measured region.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <vector>

#include "counting_new.h"
#include "duet/io/motion_file.h"
#include "duet/motion/retarget.h"
#include "duet/motion/rig_variants.h"

namespace duet {
namespace {

TEST(Retargeter, PerFrameCallAllocatesNothing) {
  MotionLoadOptions options;
  options.frame_rate = 60.0;
  Result<LoadedMotion> salsa =
      load_motion({std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/60/60_01_scaled.bvh"}, options);
  Result<LoadedMotion> rig = load_motion({std::string(DUET_DATA_DIR) + "/cmu-handshake/18_01.bvh"});
  ASSERT_TRUE(salsa.ok() && rig.ok());
  const Clip& source = salsa.value().clip;
  Result<Retargeter> retargeter =
      Retargeter::create(source.skeleton_ptr(), salsa.value().roles,
                         rig.value().clip.skeleton_ptr(), rig.value().roles);
  ASSERT_TRUE(retargeter.ok()) << retargeter.error().message;
  const auto n = static_cast<std::size_t>(rig.value().clip.joint_count());
  std::vector<Vec3> translations(n);
  std::vector<Quat> rotations(n);

  test::g_allocations = 0;
  test::g_counting = true;
  const auto start = std::chrono::steady_clock::now();
  for (int f = 0; f < source.frame_count(); ++f) {
    retargeter.value().retarget_frame(source.translations_ls(f), source.rotations_ls(f),
                                      translations, rotations);
  }
  const auto stop = std::chrono::steady_clock::now();
  test::g_counting = false;
  EXPECT_EQ(test::g_allocations.load(), 0);
  std::printf(
      "retarget_frame, salsa (43 joints) -> handshake rig (38 joints): %.2f us per frame\n",
      std::chrono::duration<double, std::micro>(stop - start).count() / source.frame_count());
}

}  // namespace
}  // namespace duet
