// Hand contact detection on synthetic pairs: a one-second hold gives one one-second interval, a
// two-frame flicker (or a two-frame gap) is debounced, offsets are in the template hand's frame.
#include "duet/partner/hand_contacts.h"

#include <gtest/gtest.h>

#include <vector>

#include "partner/synthetic_partner.h"

namespace duet {
namespace {

constexpr double kFps = 60.0;
constexpr int kFrames = 240;

// Leader at the origin; follower beside him on his left (+X), both facing +Z. The follower's
// right hand meets the leader's left hand in the frames where `touching` says so, else the
// follower stands 2 m further away.
struct Pair {
  std::shared_ptr<const Skeleton> skeleton = test::make_humanoid();
  JointRoles roles = test::humanoid_roles(*skeleton);
  Clip leader = test::make_standing_clip(skeleton, kFrames, kFps);
  Clip follower = test::make_standing_clip(skeleton, kFrames, kFps);

  explicit Pair(const std::vector<bool>& touching) {
    const test::WorldPose rest = test::world_pose(leader, 0);
    const Vec3 leader_left = rest.positions[static_cast<std::size_t>(roles[Role::kLeftWrist])];
    const Vec3 right_from_root =
        rest.positions[static_cast<std::size_t>(roles[Role::kRightWrist])] - rest.positions[0];
    for (int f = 0; f < kFrames; ++f) {
      // The follower's right wrist on the leader's left wrist, or 2 m away.
      const Vec3 wrist =
          leader_left + Vec3(touching[static_cast<std::size_t>(f)] ? 0.0 : 2.0, 0, 0);
      follower.translations_ls(f)[0] = wrist - right_from_root;
    }
  }
};

std::vector<bool> frames_between(int begin, int end) {
  std::vector<bool> t(kFrames, false);
  for (int f = begin; f < end; ++f) t[static_cast<std::size_t>(f)] = true;
  return t;
}

const int kLeftRight = hand_pair(Side::kLeft, Side::kRight);

TEST(HandContacts, PairIndexing) {
  EXPECT_EQ(kHandPairCount, 4);
  for (int p = 0; p < kHandPairCount; ++p) {
    EXPECT_EQ(hand_pair(template_side(p), response_side(p)), p);
  }
  EXPECT_EQ(hand_pair_name(kLeftRight), "left-right");
}

TEST(HandContacts, OneSecondHoldGivesOneIntervalOfOneSecond) {
  Pair pair(frames_between(60, 120));
  const Result<HandContacts> r =
      HandContacts::detect(pair.leader, pair.roles, pair.follower, pair.roles);
  ASSERT_TRUE(r.ok()) << r.error().message;
  const HandContacts& c = r.value();
  EXPECT_EQ(c.frame_count(), kFrames);
  ASSERT_EQ(c.intervals(kLeftRight).size(), 1u);
  const ContactInterval& i = c.intervals(kLeftRight)[0];
  EXPECT_EQ(i.begin_frame, 60);
  EXPECT_EQ(i.end_frame, 120);
  EXPECT_DOUBLE_EQ(i.begin_s, 1.0);
  EXPECT_DOUBLE_EQ(i.duration_s, 1.0);
  EXPECT_DOUBLE_EQ(c.contact_fraction(kLeftRight), 0.25);
  EXPECT_DOUBLE_EQ(c.any_contact_fraction(), 0.25);
  for (int p = 0; p < kHandPairCount; ++p) {
    if (p != kLeftRight) {
      EXPECT_TRUE(c.intervals(p).empty()) << hand_pair_name(p);
    }
  }
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_EQ(c.in_contact(f, kLeftRight), f >= 60 && f < 120) << f;
    EXPECT_EQ(c.mask(f), (f >= 60 && f < 120) ? (1u << kLeftRight) : 0u) << f;
  }
  EXPECT_DOUBLE_EQ(c.box_gap(90, kLeftRight), 0.0);
  EXPECT_GT(c.box_gap(10, kLeftRight), 1.0);
}

TEST(HandContacts, TwoFrameFlickersAndGapsAreDebounced) {
  std::vector<bool> touching = frames_between(60, 120);
  touching[90] = touching[91] = false;   // a two-frame gap inside the hold
  touching[180] = touching[181] = true;  // a two-frame flicker on its own
  Pair pair(touching);
  const HandContacts c =
      HandContacts::detect(pair.leader, pair.roles, pair.follower, pair.roles).value();
  EXPECT_FALSE(c.raw_contact(90, kLeftRight));
  EXPECT_TRUE(c.raw_contact(180, kLeftRight));
  ASSERT_EQ(c.intervals(kLeftRight).size(), 1u);
  EXPECT_EQ(c.intervals(kLeftRight)[0].begin_frame, 60);
  EXPECT_EQ(c.intervals(kLeftRight)[0].end_frame, 120);
  EXPECT_TRUE(c.in_contact(90, kLeftRight));
  EXPECT_FALSE(c.in_contact(180, kLeftRight));

  // Without debouncing both survive.
  ContactOptions raw;
  raw.min_gap_s = 0.0;
  raw.min_contact_s = 0.0;
  const HandContacts r =
      HandContacts::detect(pair.leader, pair.roles, pair.follower, pair.roles, raw).value();
  EXPECT_EQ(r.intervals(kLeftRight).size(), 3u);
}

TEST(HandContacts, PaddingDecidesWhatTouches) {
  Pair pair(frames_between(60, 120));
  ContactOptions tight;
  tight.padding_m = 0.0;  // boxes must overlap
  EXPECT_EQ(HandContacts::detect(pair.leader, pair.roles, pair.follower, pair.roles, tight)
                .value()
                .intervals(kLeftRight)
                .size(),
            1u);
  ContactOptions huge;
  huge.padding_m = 1.5;  // 3 m: every pair touches all the time
  const HandContacts c =
      HandContacts::detect(pair.leader, pair.roles, pair.follower, pair.roles, huge).value();
  EXPECT_DOUBLE_EQ(c.any_contact_fraction(), 1.0);
}

TEST(HandContacts, OffsetIsInTheTemplateHandFrame) {
  Pair pair(frames_between(0, kFrames));
  // Turn the leader so his hand frame differs from the world's.
  for (int f = 0; f < kFrames; ++f) pair.leader.rotations_ls(f)[0] = yaw_rotation(0.01 * f);
  const HandContacts c =
      HandContacts::detect(pair.leader, pair.roles, pair.follower, pair.roles).value();
  for (const int f : {0, 100, 239}) {
    const test::WorldPose l = test::world_pose(pair.leader, f);
    const test::WorldPose r = test::world_pose(pair.follower, f);
    for (int p = 0; p < kHandPairCount; ++p) {
      const auto tw = static_cast<std::size_t>(
          pair.roles[template_side(p) == Side::kLeft ? Role::kLeftWrist : Role::kRightWrist]);
      const auto rw = static_cast<std::size_t>(
          pair.roles[response_side(p) == Side::kLeft ? Role::kLeftWrist : Role::kRightWrist]);
      const Vec3 rebuilt = l.positions[tw] + l.rotations[tw] * c.offset_ls(f, p);
      EXPECT_LT((rebuilt - r.positions[rw]).norm(), 1e-12);
    }
  }
  // Between frames: the lerp of the two nearest; clamped outside the clip.
  for (int p = 0; p < kHandPairCount; ++p) {
    const Vec3 mid = 0.75 * c.offset_ls(100, p) + 0.25 * c.offset_ls(101, p);
    EXPECT_LT((c.offset_ls_at(100.25, p) - mid).norm(), 1e-12);
    EXPECT_EQ(c.offset_ls_at(-5.0, p), c.offset_ls(0, p));
    EXPECT_EQ(c.offset_ls_at(1e9, p), c.offset_ls(kFrames - 1, p));
  }
}

TEST(HandContacts, BadInputIsAnError) {
  Pair pair(frames_between(60, 120));
  const Clip shorter = test::make_standing_clip(pair.skeleton, kFrames - 1, kFps);
  const Result<HandContacts> frames =
      HandContacts::detect(pair.leader, pair.roles, shorter, pair.roles);
  ASSERT_FALSE(frames.ok());
  EXPECT_NE(frames.error().message.find("frames"), std::string::npos);

  const Clip slower = test::make_standing_clip(pair.skeleton, kFrames, 30.0);
  EXPECT_FALSE(HandContacts::detect(pair.leader, pair.roles, slower, pair.roles).ok());

  JointRoles broken = pair.roles;
  broken.joints[static_cast<std::size_t>(Role::kRightWrist)] = -1;
  const Result<HandContacts> roles =
      HandContacts::detect(pair.leader, pair.roles, pair.follower, broken);
  ASSERT_FALSE(roles.ok());
  EXPECT_NE(roles.error().message.find("right_wrist"), std::string::npos) << roles.error().message;

  ContactOptions negative;
  negative.padding_m = -0.1;
  EXPECT_FALSE(
      HandContacts::detect(pair.leader, pair.roles, pair.follower, pair.roles, negative).ok());
}

TEST(Debounce, FillsInnerGapsThenDropsShortRuns) {
  const auto run = [](std::vector<bool> t, int gap, int contact) {
    debounce(t, gap, contact);
    std::string s;
    for (const bool b : t) s += b ? '#' : '.';
    return s;
  };
  const auto track = [](const std::string& s) {
    std::vector<bool> t;
    for (const char c : s) t.push_back(c == '#');
    return t;
  };
  EXPECT_EQ(run(track("..####..####.."), 3, 3), "..##########..");
  EXPECT_EQ(run(track("..####...####."), 3, 3), "..####...####.");
  EXPECT_EQ(run(track(".##.....#####."), 3, 3), "........#####.");
  // Gaps at the ends are not between two contacts and stay.
  EXPECT_EQ(run(track(".####."), 5, 1), ".####.");
  EXPECT_EQ(run(track("##..##"), 0, 3), "......");
  EXPECT_EQ(run(track(""), 3, 3), "");
}

}  // namespace
}  // namespace duet
