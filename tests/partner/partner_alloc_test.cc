// The per-frame path allocates nothing after set-up (architecture.md: run time). This file
// replaces the global operator new of the partner test program with a counting one; counting is
// on only inside the measured region.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "duet/partner/partner_synthesis.h"
#include "partner/synthetic_partner.h"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};

void* counted_alloc(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* counted_aligned_alloc(std::size_t size, std::align_val_t align) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  const auto a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t size) { return counted_alloc(size); }
void* operator new[](std::size_t size) { return counted_alloc(size); }
void* operator new(std::size_t size, std::align_val_t align) {
  return counted_aligned_alloc(size, align);
}
void* operator new[](std::size_t size, std::align_val_t align) {
  return counted_aligned_alloc(size, align);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace duet {
namespace {

TEST(PartnerSynthesis, PerFrameCallAllocatesNothing) {
  const auto skeleton = test::make_humanoid();
  const JointRoles roles = test::humanoid_roles(*skeleton);
  Clip leader = test::make_standing_clip(skeleton, 200);
  Clip follower = test::make_standing_clip(skeleton, 200);
  // Hands together in the middle of the take, the follower sliding a little.
  const test::WorldPose rest = test::world_pose(leader, 0);
  const Vec3 from_root =
      rest.positions[static_cast<std::size_t>(roles[Role::kRightWrist])] - rest.positions[0];
  for (int f = 0; f < 200; ++f) {
    const Vec3 wrist = rest.positions[static_cast<std::size_t>(roles[Role::kLeftWrist])];
    follower.translations_ls(f)[0] =
        wrist - from_root + Vec3(f > 50 && f < 150 ? 0.0 : 1.0, 0, 0.001 * f);
  }
  const PartnerModel model = PartnerModel::build(leader, roles, follower, roles).value();
  PartnerParams params;  // everything on, the foot hold too
  params.foot_hold.enabled = true;
  PartnerContext context(skeleton->joint_count());
  std::vector<Vec3> t(skeleton->joints.size());
  std::vector<Quat> r(skeleton->joints.size());
  std::vector<UserPose> users;
  for (int f = 0; f < 200; ++f) {
    const test::WorldPose w = test::world_pose(leader, f);
    users.push_back(user_pose_from_world(w.positions, w.rotations, roles));
    users.back().wrist_positions_ws[0].y() += 0.05;
  }

  g_allocations = 0;
  g_counting = true;
  bool ok = true;
  for (int i = 0; i < 1000; ++i) {
    const int frame = (i * 7 / 5) % 200;
    PartnerFrameInfo info;
    PartnerSynthesisJob job;
    job.model = &model;
    job.params = &params;
    job.frame = frame;
    job.jumped = i % 97 == 0;
    job.dt_s = 1.0 / 60;
    job.translations_ls = follower.translations_ls(frame);
    job.rotations_ls = follower.rotations_ls(frame);
    job.user = &users[static_cast<std::size_t>(frame)];
    job.context = &context;
    job.translations_ls_out = t;
    job.rotations_ls_out = r;
    job.info = &info;
    ok = job.run() && ok;
  }
  g_counting = false;
  EXPECT_TRUE(ok);
  EXPECT_EQ(g_allocations.load(), 0);
}

}  // namespace
}  // namespace duet
