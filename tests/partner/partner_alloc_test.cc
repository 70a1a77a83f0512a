// The per-frame path allocates nothing after set-up (architecture.md: run time). This file
// replaces the global operator new of the partner test program with a counting one
// (counting_new.h); counting is on only inside the measured region.
#include <gtest/gtest.h>

#include <vector>

#include "counting_new.h"
#include "duet/live/wrists_on_user_body.h"
#include "duet/partner/partner_synthesis.h"
#include "features/synthetic_dancer.h"
#include "partner/synthetic_partner.h"

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
  PartnerContext context(skeleton->joint_count());
  std::vector<Vec3> t(skeleton->joints.size());
  std::vector<Quat> r(skeleton->joints.size());
  std::vector<UserPose> users;
  for (int f = 0; f < 200; ++f) {
    const test::WorldPose w = test::world_pose(leader, f);
    users.push_back(user_pose_from_world(w.positions, w.rotations, roles));
    users.back().wrist_positions_ws[0].y() += 0.05;
    users.back().wrist_body_difference_hs[0] = Vec3(0.03, 0.0, 0.02);  // the base arm's path
  }

  test::g_allocations = 0;
  test::g_counting = true;
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
  test::g_counting = false;
  EXPECT_TRUE(ok);
  EXPECT_EQ(test::g_allocations.load(), 0);
}

TEST(WristsOnUserBody, PerFrameCallAllocatesNothing) {
  auto skeleton = testing::make_role_skeleton();
  LoadedMotion dancer;
  dancer.clip = testing::make_dance(skeleton, 60.0, 120);
  dancer.roles = testing::daz_roles(*skeleton);
  auto longer = std::make_shared<Skeleton>(*skeleton);
  for (Joint& joint : longer->joints) joint.offset *= 1.1;
  SourceSkeleton user;
  user.skeleton = longer;
  user.roles = testing::daz_roles(*longer);
  WristsOnUserBody wrists = WristsOnUserBody::create({&dancer}, user).value();
  double sum = 0.0;
  test::g_allocations = 0;
  test::g_counting = true;
  for (int i = 0; i < 500; ++i) sum += wrists.wrist_difference_hs(0, 0.37 * i)[0].norm();
  test::g_counting = false;
  EXPECT_EQ(test::g_allocations, 0);
  EXPECT_GT(sum, 0.0);
}

}  // namespace
}  // namespace duet
