#include "duet/features/feature_extractor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "features/synthetic_dancer.h"

namespace duet {
namespace {

using testing::daz_roles;
using testing::make_dance;
using testing::make_role_skeleton;

class FeatureExtractorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    skeleton_ = make_role_skeleton();
    ASSERT_EQ(skeleton_->validate(), "");
    Result<FeatureExtractor> e = FeatureExtractor::create(skeleton_, daz_roles(*skeleton_), spec_);
    ASSERT_TRUE(e) << e.error().message;
    extractor_.emplace(std::move(e).value());
  }
  FeatureSpec spec_;
  std::shared_ptr<Skeleton> skeleton_;
  std::optional<FeatureExtractor> extractor_;
};

TEST_F(FeatureExtractorTest, OnlineFramesEqualTheBatchExtraction) {
  const Clip clip = make_dance(skeleton_, 60.0, 300);
  const FeatureMatrix batch = extractor_->extract_clip(clip);
  auto context = extractor_->make_context();
  std::vector<float> row(static_cast<std::size_t>(extractor_->dimension()));
  for (int f = 0; f < clip.frame_count(); ++f) {
    extractor_->extract(context, clip.translations_ls(f), clip.rotations_ls(f), f / 60.0, row);
    for (int d = 0; d < extractor_->dimension(); ++d) {
      ASSERT_EQ(row[static_cast<std::size_t>(d)], batch(f, d)) << "frame " << f << " dim " << d;
    }
  }
}

TEST_F(FeatureExtractorTest, DoesNotDependOnPlaceOrFacingInTheRoom) {
  const Clip clip = make_dance(skeleton_, 60.0, 200);
  Clip moved = clip;
  const Quat turn = yaw_rotation(2.1);
  for (int f = 0; f < moved.frame_count(); ++f) {
    moved.translations_ls(f)[0] = turn * clip.translations_ls(f)[0] + Vec3(3, 0, -2);
    moved.rotations_ls(f)[0] = turn * clip.rotations_ls(f)[0];
  }
  const FeatureMatrix a = extractor_->extract_clip(clip);
  const FeatureMatrix b = extractor_->extract_clip(moved);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-4f);
}

TEST_F(FeatureExtractorTest, ALimbsDimensionsAreTheOnesItsJointsMove) {
  // Each limb's bend (elbow, knee) changes that limb's posture dimensions and no others.
  const std::vector<std::vector<int>> limbs = spec_.limb_dims();
  ASSERT_EQ(limbs.size(), 4u);
  const Clip clip = make_dance(skeleton_, 60.0, 60);
  const FeatureMatrix plain = extractor_->extract_clip(clip);
  const JointRoles roles = daz_roles(*skeleton_);
  const Role bends[] = {Role::kLeftElbow, Role::kRightElbow, Role::kLeftKnee, Role::kRightKnee};
  for (std::size_t limb = 0; limb < limbs.size(); ++limb) {
    EXPECT_EQ(limbs[limb].size(), 9u) << "two bones and an end point";
    Clip bent = clip;
    for (int f = 0; f < bent.frame_count(); ++f) {
      Quat& rotation = bent.rotations_ls(f)[static_cast<std::size_t>(roles[bends[limb]])];
      rotation = rotation * Quat(Eigen::AngleAxisd(0.4, Vec3(1, 0, 1).normalized()));
    }
    const FeatureMatrix moved = extractor_->extract_clip(bent);
    int changed_inside = 0;
    for (int d = 0; d < spec_.posture_dims(); ++d) {
      const bool changed = (moved.col(d) - plain.col(d)).cwiseAbs().maxCoeff() > 1e-4f;
      const bool inside = std::count(limbs[limb].begin(), limbs[limb].end(), d) > 0;
      EXPECT_FALSE(changed && !inside) << "limb " << limb << " moved dimension " << d;
      changed_inside += changed && inside;
    }
    EXPECT_GE(changed_inside, 4) << "limb " << limb;
  }
  // Three points' posture is the hands: no limb of its own to bound.
  FeatureSpec head_hands;
  head_hands.input_points = InputPoints::kHeadHands;
  EXPECT_TRUE(head_hands.limb_dims().empty());
}

TEST_F(FeatureExtractorTest, VelocitiesAreRealSpeedsAtAnyInputRate) {
  // A body gliding forward at 1.5 m/s while it turns: forward speed 1.5 m/s whatever the rate, in
  // leg lengths per second.
  for (double fps : {30.0, 60.0, 120.0}) {
    Clip clip(skeleton_, fps, static_cast<int>(fps));
    for (int f = 0; f < clip.frame_count(); ++f) {
      const double t = f / fps;
      const double yaw = 0.5 * t;
      clip.rotations_ls(f)[0] = yaw_rotation(yaw);
      clip.translations_ls(f)[0] = Vec3(0, 0.9, 0) + 1.5 * t * (yaw_rotation(0.0) * Vec3::UnitZ());
    }
    const FeatureMatrix rows = extractor_->extract_clip(clip);
    const int root = spec_.block_begin(FeatureBlock::kRootVelocity);
    const int last = clip.frame_count() - 1;
    const double yaw = 0.5 * last / fps;
    const double legs = extractor_->leg_length_m();
    EXPECT_NEAR(legs, 0.84, 1e-9);
    EXPECT_NEAR(rows(last, root), 1.5 * std::cos(yaw) / legs, 0.05) << fps;  // forward
    EXPECT_NEAR(rows(last, root + 3), 0.5, 1e-3) << fps;                // yaw rate
  }
}

TEST_F(FeatureExtractorTest, NanPoseGivesNanFeaturesAndDoesNotPoisonLaterFrames) {
  const Clip clip = make_dance(skeleton_, 60.0, 40);
  const FeatureMatrix clean = extractor_->extract_clip(clip);
  auto context = extractor_->make_context();
  std::vector<float> row(static_cast<std::size_t>(extractor_->dimension()));
  Pose pose;
  for (int f = 0; f < clip.frame_count(); ++f) {
    clip.pose_at(f, pose);
    if (f == 20) pose.rotations_ls[3] = Quat(std::nanf(""), 0, 0, 0);
    extractor_->extract(context, pose.translations_ls, pose.rotations_ls, f / 60.0, row);
    if (f == 20) {
      EXPECT_TRUE(std::isnan(row[0]));
    } else {
      for (float v : row) ASSERT_TRUE(std::isfinite(v)) << "frame " << f;
    }
  }
  // The last frame's features (window 0.1 s = 6 frames, back past frame 20) match the clean run.
  for (int d = 0; d < extractor_->dimension(); ++d) {
    EXPECT_NEAR(row[static_cast<std::size_t>(d)], clean(39, d), 1e-5);
  }
}

TEST_F(FeatureExtractorTest, MissingRoleIsAClearError) {
  JointRoles roles = daz_roles(*skeleton_);
  roles.joints[static_cast<std::size_t>(Role::kLeftWrist)] = -1;
  Result<FeatureExtractor> e = FeatureExtractor::create(skeleton_, roles, spec_);
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message.find("left_wrist"), std::string::npos);
}

// The same body and motion on another rig: every joint's local axes turned by its own constant
// rotation, an extra (twist) joint in each forearm, another unit of length and a 1.2x bigger body.
// The world pose is the same up to scale, so the features must be the same.
TEST_F(FeatureExtractorTest, SameMotionOnAnotherRigGivesTheSameFeatures) {
  const Clip clip = make_dance(skeleton_, 60.0, 240);
  const double scale = 1.2 * 100.0;  // a 1.2x body, in centimetres
  const int n = skeleton_->joint_count();
  std::vector<Quat> axes(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) {
    axes[static_cast<std::size_t>(j)] = exp_map(Vec3(0.7 * std::sin(j), 1.3 * std::cos(2.0 * j), 0.4 * j));
  }
  // Old joint j -> new index; each elbow gets a twist joint halfway along the forearm.
  auto rig = std::make_shared<Skeleton>();
  std::vector<int> new_index(static_cast<std::size_t>(n), -1);
  const std::array<int, 2> elbows = {static_cast<int>(Role::kLeftElbow),
                                     static_cast<int>(Role::kRightElbow)};
  std::vector<int> twist_of(static_cast<std::size_t>(n), -1);
  for (int j = 0; j < n; ++j) {
    const Joint& old = skeleton_->joints[static_cast<std::size_t>(j)];
    Joint joint = old;
    joint.name = "bone" + std::to_string(j);
    const int parent = old.parent < 0 ? -1 : old.parent;
    const int attach = parent >= 0 && twist_of[static_cast<std::size_t>(parent)] >= 0
                           ? twist_of[static_cast<std::size_t>(parent)]
                           : (parent >= 0 ? new_index[static_cast<std::size_t>(parent)] : -1);
    const Quat parent_axes = parent >= 0 ? axes[static_cast<std::size_t>(parent)] : Quat::Identity();
    Vec3 offset = parent_axes.conjugate() * (old.offset * scale);
    if (attach != (parent >= 0 ? new_index[static_cast<std::size_t>(parent)] : -1)) {
      offset *= 0.5;  // the twist joint took the first half of the bone
    }
    joint.parent = attach;
    joint.offset = offset;
    new_index[static_cast<std::size_t>(j)] = rig->joint_count();
    rig->joints.push_back(joint);
    if (std::ranges::find(elbows, j) != elbows.end()) {
      // The twist joint: halfway to the wrist (the elbow's only child), no rotation of its own.
      Joint twist;
      twist.name = "twist" + std::to_string(j);
      twist.parent = new_index[static_cast<std::size_t>(j)];
      const Vec3 to_wrist = skeleton_->joints[static_cast<std::size_t>(j + 1)].offset * scale;
      twist.offset = axes[static_cast<std::size_t>(j)].conjugate() * (0.5 * to_wrist);
      twist.channels = old.channels;
      twist_of[static_cast<std::size_t>(j)] = rig->joint_count();
      rig->joints.push_back(twist);
    }
  }
  ASSERT_EQ(rig->validate(), "");
  JointRoles roles;
  roles.convention = "test-rig";
  for (int r = 0; r < kRoleCount; ++r) roles.joints[static_cast<std::size_t>(r)] = new_index[static_cast<std::size_t>(r)];

  Clip moved(rig, clip.frame_rate(), clip.frame_count());
  for (int f = 0; f < clip.frame_count(); ++f) {
    auto rotations = moved.rotations_ls(f);
    for (int j = 0; j < n; ++j) {
      const Joint& old = skeleton_->joints[static_cast<std::size_t>(j)];
      const Quat parent_axes =
          old.parent >= 0 ? axes[static_cast<std::size_t>(old.parent)] : Quat::Identity();
      // World rotation W'_j = W_j C_j, so the local one is C_parent^-1 q_j C_j.
      rotations[static_cast<std::size_t>(new_index[static_cast<std::size_t>(j)])] =
          parent_axes.conjugate() * clip.rotations_ls(f)[static_cast<std::size_t>(j)] *
          axes[static_cast<std::size_t>(j)];
    }
    for (int elbow : elbows) {
      // The twist joint keeps the elbow's axes: identity local rotation.
      rotations[static_cast<std::size_t>(twist_of[static_cast<std::size_t>(elbow)])] = Quat::Identity();
    }
    moved.translations_ls(f)[0] = clip.translations_ls(f)[0] * scale;
    for (int j = 1; j < rig->joint_count(); ++j) {
      moved.translations_ls(f)[static_cast<std::size_t>(j)] = rig->joints[static_cast<std::size_t>(j)].offset;
    }
  }
  // The wrists hang below the twist joints now: their offsets are the other half of the forearm.
  for (int elbow : elbows) {
    const int wrist = new_index[static_cast<std::size_t>(elbow + 1)];
    for (int f = 0; f < moved.frame_count(); ++f) {
      moved.translations_ls(f)[static_cast<std::size_t>(wrist)] = rig->joints[static_cast<std::size_t>(wrist)].offset;
    }
  }
  Result<FeatureExtractor> other = FeatureExtractor::create(rig, roles, spec_);
  ASSERT_TRUE(other) << other.error().message;
  EXPECT_NEAR(other.value().leg_length_m() / extractor_->leg_length_m(), scale, 1e-9);
  const FeatureMatrix a = extractor_->extract_clip(clip);
  const FeatureMatrix b = other.value().extract_clip(moved);
  ASSERT_EQ(a.cols(), b.cols());
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-4f);
}

// Another body's proportions: shoulders 1.8x as wide, arms 1.3x as long, every joint turned the
// same way (each segment's direction kept). A hand's speed is measured along a standard arm
// (FeatureSpec::standard_arm_speeds), so the hands' speeds are the same; measured on the rig's own
// hands they are not.
TEST_F(FeatureExtractorTest, WiderShouldersAndLongerArmsGiveTheSameHandSpeeds) {
  const Clip clip = make_dance(skeleton_, 60.0, 240);
  auto rig = std::make_shared<Skeleton>(*skeleton_);
  const auto joint = [&](Role role) -> Joint& {
    return rig->joints[static_cast<std::size_t>(static_cast<int>(role))];
  };
  for (Role shoulder : {Role::kLeftShoulder, Role::kRightShoulder})
    joint(shoulder).offset.x() *= 1.8;
  for (Role bone : {Role::kLeftElbow, Role::kLeftWrist, Role::kRightElbow, Role::kRightWrist}) {
    joint(bone).offset *= 1.3;
  }
  Clip moved(rig, clip.frame_rate(), clip.frame_count());
  for (int f = 0; f < clip.frame_count(); ++f) {
    std::ranges::copy(clip.rotations_ls(f), moved.rotations_ls(f).begin());
    moved.translations_ls(f)[0] = clip.translations_ls(f)[0];
    for (int j = 1; j < rig->joint_count(); ++j) {
      moved.translations_ls(f)[static_cast<std::size_t>(j)] =
          rig->joints[static_cast<std::size_t>(j)].offset;
    }
  }
  const int hands = spec_.block_begin(FeatureBlock::kEffectorSpeed);
  const auto largest_hand_speed_difference = [&](const FeatureSpec& spec) {
    const FeatureExtractor mine =
        FeatureExtractor::create(skeleton_, daz_roles(*skeleton_), spec).value();
    const FeatureExtractor theirs = FeatureExtractor::create(rig, daz_roles(*rig), spec).value();
    const FeatureMatrix a = mine.extract_clip(clip);
    const FeatureMatrix b = theirs.extract_clip(moved);
    return (a.middleCols(hands, 2) - b.middleCols(hands, 2)).cwiseAbs().maxCoeff();
  };
  ASSERT_TRUE(spec_.standard_arm_speeds);
  EXPECT_LT(largest_hand_speed_difference(spec_), 1e-4f);
  FeatureSpec measured = spec_;
  measured.standard_arm_speeds = false;
  EXPECT_GT(largest_hand_speed_difference(measured), 0.1f);
}

// A speed is a length, so a sensor's white noise only adds to it (FeatureSpec::debiased_speeds):
// the same dance with 3 degrees of noise per joint and axis, and the dancer standing still with
// it. Kept, the noise's share makes every speed higher than the clean one on average (a dancer
// standing still moves the hands and feet at a dancing pace); taken off, a dancing speed is the
// clean one on average, and a still one less than half as far from zero (a length cannot go below
// it, so what is left of the noise there stays positive); every speed is nearer the clean one
// frame by frame. Clean input keeps its speeds.
TEST_F(FeatureExtractorTest, ASensorsNoiseIsTakenOffTheEffectorsSpeeds) {
  const Clip dance = make_dance(skeleton_, 60.0, 600);
  Clip still = dance;
  for (int f = 0; f < still.frame_count(); ++f) {
    std::ranges::copy(dance.rotations_ls(0), still.rotations_ls(f).begin());
    std::ranges::copy(dance.translations_ls(0), still.translations_ls(f).begin());
  }
  std::mt19937 random(11);
  std::normal_distribution<double> noise_rad(0.0, deg_to_rad(3.0));
  const auto noisy = [&](const Clip& clean) {
    Clip out = clean;
    for (int f = 0; f < out.frame_count(); ++f) {
      for (Quat& q : out.rotations_ls(f)) {
        const Vec3 turn(noise_rad(random), noise_rad(random), noise_rad(random));
        q = (q * Quat(Eigen::AngleAxisd(turn.norm(), turn.normalized()))).normalized();
      }
    }
    return out;
  };
  const int speeds = spec_.block_begin(FeatureBlock::kEffectorSpeed);
  FeatureSpec raw_spec = spec_;
  raw_spec.debiased_speeds = false;
  const FeatureExtractor raw =
      FeatureExtractor::create(skeleton_, daz_roles(*skeleton_), raw_spec).value();
  ASSERT_TRUE(spec_.debiased_speeds);
  // Over effectors and frames (after the first second): the mean of speed - the clean speed
  // (the bias) and of its size.
  struct Error {
    double bias, size;
  };
  const auto speed_error = [&](const FeatureExtractor& extractor, const Clip& clean,
                               const Clip& sensed) {
    const FeatureMatrix truth = extractor.extract_clip(clean);
    const FeatureMatrix measured = extractor.extract_clip(sensed);
    const int from = 60;
    const Eigen::MatrixXf error = (measured.middleCols(speeds, 4) - truth.middleCols(speeds, 4))
                                      .bottomRows(truth.rows() - from);
    return Error{error.mean(), error.cwiseAbs().mean()};
  };
  for (const Clip* clean : std::array<const Clip*, 2>{&dance, &still}) {
    const Clip sensed = noisy(*clean);
    const Error kept = speed_error(raw, *clean, sensed);
    const Error taken_off = speed_error(*extractor_, *clean, sensed);
    const bool standing = clean == &still;
    SCOPED_TRACE(standing ? "standing still" : "dancing");
    EXPECT_GT(kept.bias, 0.5);  // leg lengths per second
    EXPECT_LT(std::abs(taken_off.bias), (standing ? 0.5 : 0.1) * kept.bias);
    EXPECT_LT(taken_off.size, kept.size);
  }

  const FeatureMatrix a = raw.extract_clip(dance);
  const FeatureMatrix b = extractor_->extract_clip(dance);
  EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.0f);
}

TEST(FeatureNormalizer, FloorsTinyDeviationsAndWeighsBlocks) {
  FeatureSpec spec;
  spec.posture_segments = {{Role::kHips, Role::kChest}};  // 3 + 4 + 4 = 11 dims
  spec.posture_points.clear();
  FeatureMatrix raw = FeatureMatrix::Zero(100, spec.dimension());
  for (int f = 0; f < 100; ++f) {
    raw(f, 0) = static_cast<float>(f % 2);  // std 0.5
    raw(f, 1) = 1e-6f * static_cast<float>(f % 2);  // nearly constant: floored
  }
  const FeatureNormalizer n = FeatureNormalizer::fit(raw, spec);
  EXPECT_NEAR(n.scale()[0], spec.posture_weight / (std::sqrt(3.0) * 0.5), 1e-5);
  EXPECT_NEAR(n.scale()[1], spec.posture_weight / (std::sqrt(3.0) * spec.posture_std_floor),
              1e-4);
  EXPECT_NEAR(n.scale()[spec.block_begin(FeatureBlock::kRootVelocity) + 3],
              spec.root_velocity_weight / (2.0 * spec.yaw_rate_std_floor_radps), 1e-4);
  FeatureMatrix rows = raw;
  n.apply(rows);
  EXPECT_NEAR(rows.col(0).mean(), 0.0f, 1e-5f);
  EXPECT_TRUE(rows.allFinite());

  // Three points weigh their posture block by head_hands_posture_weight, not posture_weight.
  FeatureSpec points;
  points.input_points = InputPoints::kHeadHands;
  points.posture_weight = 9.0;  // not used for three points
  FeatureMatrix raw_points = FeatureMatrix::Zero(100, points.dimension());
  for (int f = 0; f < 100; ++f) raw_points(f, 0) = static_cast<float>(f % 2);  // std 0.5
  const FeatureNormalizer p = FeatureNormalizer::fit(raw_points, points);
  EXPECT_NEAR(p.scale()[0],
              points.head_hands_posture_weight / (std::sqrt(points.posture_dims()) * 0.5), 1e-5);
}

}  // namespace
}  // namespace duet
