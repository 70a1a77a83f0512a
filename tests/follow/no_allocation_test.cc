// The per-frame path allocates nothing after set-up: malloc itself is counted (Eigen allocates
// with malloc, not operator new). Skipped under AddressSanitizer, which owns malloc.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "duet/follow/beam_follower.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/naive_hmm.h"
#include "duet/follow/nearest_neighbour.h"
#include "duet/follow/online_dtw.h"
#include "follow/synthetic.h"

#if defined(__SANITIZE_ADDRESS__) || !defined(__GLIBC__)
#define DUET_COUNT_MALLOC 0
#else
#define DUET_COUNT_MALLOC 1
#endif

#if DUET_COUNT_MALLOC
namespace {
int g_allocations = 0;
bool g_counting = false;
}  // namespace

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);

void* malloc(std::size_t size) {
  if (g_counting) ++g_allocations;
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  if (g_counting) ++g_allocations;
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) {
  if (g_counting) ++g_allocations;
  return __libc_realloc(pointer, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  if (g_counting) ++g_allocations;
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  if (g_counting) ++g_allocations;
  *out = __libc_memalign(alignment, size);
  return *out ? 0 : 12;  // ENOMEM
}
}
#endif

namespace duet {
namespace {

TEST(NoAllocation, StepsAllocateNothing) {
#if !DUET_COUNT_MALLOC
  GTEST_SKIP() << "malloc is not ours to count in this build";
#else
  // The counter works: a vector allocates.
  g_allocations = 0;
  g_counting = true;
  auto* escaped = new std::vector<float>(100);
  g_counting = false;
  delete escaped;
  ASSERT_GT(g_allocations, 0);

  const TemplateModel model = test::make_model({300, 200}, 60, 2);
  HmmFollower hmm = HmmFollower::create(model, {}).value();
  HmmFollower l2r = HmmFollower::create(model, FollowParams::left_to_right()).value();
  FollowParams sharp;
  sharp.emission_sigma = 0.05f;  // takes the emission's slow path too
  HmmFollower hmm_sharp = HmmFollower::create(model, sharp).value();
  NaiveHmmFollower naive = NaiveHmmFollower::create(model, {}).value();
  NearestNeighbourTracker nn = NearestNeighbourTracker::create(model, {}).value();
  OnlineDtwTracker dtw = OnlineDtwTracker::create(model, {}).value();
  BeamFollower beam = BeamFollower::create(model, {}).value();
  BeamFollower beam_paper =
      BeamFollower::create(model, FollowParams::paper(),
                           BeamParams::suited_to(FollowParams::paper()))
          .value();
  BeamParams few;  // one nearest candidate: most frames widen to the radius search
  few.jump_candidates = few.wide_jump_candidates = 1;
  BeamFollower beam_radius = BeamFollower::create(model, {}, few).value();
  Tracker* trackers[] = {&hmm, &l2r, &hmm_sharp, &naive, &nn, &dtw, &beam, &beam_paper,
                         &beam_radius};

  // Inputs made beforehand: exact, noisy, missing, far, at 30 Hz and late.
  std::vector<std::vector<float> > inputs;
  for (int t = 0; t < 200; ++t) inputs.push_back(test::features_at(model, (t * 7) % 500));
  inputs[50].assign(60, std::numeric_limits<float>::quiet_NaN());
  inputs[60].assign(60, 1e30f);
  const double dts[] = {1.0 / 60, 1.0 / 30, 0.2, 0.0};

  for (Tracker* tracker : trackers) {
    SCOPED_TRACE(tracker->name());
    g_allocations = 0;
    g_counting = true;
    tracker->reset();
    for (std::size_t t = 0; t < inputs.size(); ++t) {
      const FollowResult r = tracker->step(inputs[t], dts[t % 4]);
      g_counting = false;  // gtest may allocate
      ASSERT_GE(r.state, 0);
      g_counting = true;
    }
    g_counting = false;
    EXPECT_EQ(g_allocations, 0);
  }
#endif
}

}  // namespace
}  // namespace duet
