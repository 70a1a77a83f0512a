#include "duet/follow/template_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "duet/follow/follow_params.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/naive_hmm.h"
#include "duet/follow/online_dtw.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

// The error message of a failed result, or "" if it succeeded.
template <typename T>
std::string error_of(const Result<T>& result) {
  return result.ok() ? std::string() : result.error().message;
}

FeatureMatrix ones(int rows, int cols) { return FeatureMatrix::Ones(rows, cols); }

TEST(TemplateModel, BuildsAndFindsTakes) {
  Result<TemplateModel> model = TemplateModel::build(ones(10, 3), {0, 4, 7}, 60.0);
  ASSERT_TRUE(model.ok()) << error_of(model);
  const TemplateModel& m = model.value();
  EXPECT_EQ(m.num_states(), 10);
  EXPECT_EQ(m.num_dims(), 3);
  EXPECT_EQ(m.num_takes(), 3);
  EXPECT_EQ(m.take_begin(1), 4);
  EXPECT_EQ(m.take_end(1), 7);
  EXPECT_EQ(m.take_end(2), 10);
  const int expected_take[10] = {0, 0, 0, 0, 1, 1, 1, 2, 2, 2};
  for (int i = 0; i < 10; ++i) EXPECT_EQ(m.take_of(i), expected_take[i]) << i;
}

TEST(TemplateModel, AJumpIsAMoveOutOfTheBandOrIntoAnotherTake) {
  Result<TemplateModel> model = TemplateModel::build(ones(40, 2), {0, 20}, 60.0);
  ASSERT_TRUE(model.ok()) << error_of(model);
  const TemplateModel& m = model.value();
  // One step reaches 0..2 frames forward (self, next, skip).
  EXPECT_FALSE(m.is_jump(5, 5, 1));
  EXPECT_FALSE(m.is_jump(5, 7, 1));
  EXPECT_TRUE(m.is_jump(5, 8, 1));
  EXPECT_FALSE(m.is_jump(5, 11, 3));    // three steps: up to 6 frames
  EXPECT_TRUE(m.is_jump(5, 4, 1));      // back is a jump ...
  EXPECT_FALSE(m.is_jump(5, 2, 1, 3));  // ... unless within the jitter tolerance
  EXPECT_FALSE(m.is_jump(5, 10, 1, 3));
  EXPECT_TRUE(m.is_jump(5, 11, 1, 3));
  EXPECT_TRUE(m.is_jump(19, 20, 1));   // the next state is another take
  EXPECT_FALSE(m.is_jump(-1, 30, 1));  // no place yet
  EXPECT_FALSE(m.is_jump(30, -1, 1));
}

// Where each dimension sits in the blocked features, dimension by dimension.
std::vector<int> blocked_order(const TemplateModel& model) {
  std::vector<int> at;
  for (int d = 0; d < model.num_dims(); ++d) at.push_back(model.blocked_dim(d));
  return at;
}

TEST(TemplateModel, LimbsNamePostureDimensionsOnceEach) {
  TemplateModel model = TemplateModel::build(ones(4, 6), {}, 60.0, 2).value();  // posture 0..3
  EXPECT_TRUE(model.limbs().empty());
  EXPECT_TRUE(model.blocked_limbs().empty());
  EXPECT_EQ(blocked_order(model), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  // The blocked features in the limbs' order: dimension 0 (in no limb), then {1, 3}, then {2},
  // then the velocities.
  ASSERT_TRUE(model.set_limbs({{1, 3}, {2}}).ok());
  EXPECT_EQ(model.limbs().size(), 2u);
  EXPECT_EQ(blocked_order(model), (std::vector<int>{0, 1, 3, 2, 4, 5}));
  ASSERT_EQ(model.blocked_limbs().size(), 2u);
  EXPECT_EQ(model.blocked_limbs()[0].begin, 1);
  EXPECT_EQ(model.blocked_limbs()[0].end, 3);
  EXPECT_EQ(model.blocked_limbs()[1].begin, 3);
  EXPECT_EQ(model.blocked_limbs()[1].end, 4);
  // A velocity dimension, a dimension past the end or in two limbs: refused, the limbs as before.
  EXPECT_NE(error_of(model.set_limbs({{4}})).find("outside the 4 posture dimensions"),
            std::string::npos);
  EXPECT_FALSE(model.set_limbs({{-1}}).ok());
  EXPECT_NE(error_of(model.set_limbs({{0, 1}, {1}})).find("dimension 1 is in two limbs"),
            std::string::npos);
  EXPECT_EQ(blocked_order(model), (std::vector<int>{0, 1, 3, 2, 4, 5}));
  EXPECT_EQ(model.blocked_limbs().size(), 2u);
  ASSERT_TRUE(model.set_limbs({}).ok());
  EXPECT_EQ(blocked_order(model), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_TRUE(model.blocked_limbs().empty());
}

TEST(TemplateModel, EmptyTakeListIsOneTake) {
  Result<TemplateModel> model = TemplateModel::build(ones(5, 2), {}, 30.0);
  ASSERT_TRUE(model.ok());
  EXPECT_EQ(model.value().num_takes(), 1);
  EXPECT_EQ(model.value().take_end(0), 5);
}

TEST(TemplateModel, BuildsFromRowMajorBuffer) {
  const std::vector<float> buffer = {1, 2, 3, 4, 5, 6};
  Result<TemplateModel> model = TemplateModel::build(buffer, 2, 3, {0}, 60.0);
  ASSERT_TRUE(model.ok());
  EXPECT_EQ(model.value().features()(1, 0), 4.0f);
  EXPECT_EQ(model.value().features()(0, 2), 3.0f);
}

TEST(TemplateModel, HoldsItsFeaturesAtHalfPrecision) {
  // 0.1 is not a binary16 value: the nearest is 0.0999755859375 (11 significant bits).
  FeatureMatrix features(2, 3);
  features << 0.1f, 1.0f, -2.5f, 1e6f, -1e6f, 3.0e-3f;
  const TemplateModel model = TemplateModel::build(features, {}, 60.0).value();
  EXPECT_EQ(model.features()(0, 0), 0.0999755859375f);
  EXPECT_EQ(model.features()(0, 1), 1.0f);
  EXPECT_EQ(model.features()(0, 2), -2.5f);
  EXPECT_EQ(model.features()(1, 0), 65504.0f);  // the largest half, not infinity
  EXPECT_EQ(model.features()(1, 1), -65504.0f);
  EXPECT_NEAR(model.features()(1, 2), 3.0e-3f, 3.0e-3f * 5e-4f);
  for (Eigen::Index i = 0; i < features.size(); ++i) {
    const float held = model.features().data()[i];
    EXPECT_EQ(TemplateModel::held_precision(held), held);  // rounding again changes nothing
  }
  // Non-finite features are still refused, not rounded to a finite value.
  features(1, 0) = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(TemplateModel::build(features, {}, 60.0));
}

TEST(TemplateModel, SharesFeaturesAlreadyAtItsPrecisionAndCopiesOthersRounded) {
  auto held = std::make_shared<std::vector<float>>(std::vector<float>{0.5f, 0.25f, 3.0f, -1.0f});
  const TemplateModel shared = TemplateModel::build_shared(held, *held, 2, 2, {}, 60.0).value();
  EXPECT_EQ(shared.features().data(), held->data());
  auto finer = std::make_shared<std::vector<float>>(std::vector<float>{0.1f, 0.25f, 3.0f, -1.0f});
  const TemplateModel copied = TemplateModel::build_shared(finer, *finer, 2, 2, {}, 60.0).value();
  EXPECT_NE(copied.features().data(), finer->data());
  EXPECT_EQ(copied.features()(0, 0), TemplateModel::held_precision(0.1f));
  EXPECT_EQ(copied.features()(1, 1), -1.0f);
  // Over every scale a half holds (subnormal halves, the largest): values at the precision are
  // shared, the float next to each is copied.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> exponent(-26.0f, 16.0f);
  std::vector<float> values = {0.0f, -0.0f, 65504.0f, -65504.0f, 0x1p-24f, 0x1p-14f, 0x3ffp-24f};
  while (values.size() < 400) {
    const float value = std::exp2(exponent(rng)) * (values.size() % 2 == 0 ? 1.0f : -1.0f);
    values.push_back(TemplateModel::held_precision(value));
  }
  auto all = std::make_shared<std::vector<float>>(values);
  const int rows = static_cast<int>(values.size()) / 2;
  EXPECT_EQ(TemplateModel::build_shared(all, *all, rows, 2, {}, 60.0).value().features().data(),
            all->data());
  for (std::size_t i = 0; i < values.size(); i += 7) {
    auto one_off = std::make_shared<std::vector<float>>(values);
    (*one_off)[i] = std::nextafter(values[i], std::numeric_limits<float>::infinity());
    const TemplateModel model =
        TemplateModel::build_shared(one_off, *one_off, rows, 2, {}, 60.0).value();
    EXPECT_NE(model.features().data(), one_off->data()) << values[i];
    EXPECT_EQ(model.features().data()[i], TemplateModel::held_precision((*one_off)[i]));
  }
}
TEST(TemplateModel, RejectsBadInputWithClearMessages) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(error_of(TemplateModel::build(FeatureMatrix(0, 3), {}, 60.0)).find("no template"),
            std::string::npos);
  EXPECT_NE(error_of(TemplateModel::build(FeatureMatrix(4, 0), {}, 60.0)).find("no template"),
            std::string::npos);

  FeatureMatrix bad = ones(4, 3);
  bad(2, 1) = nan;
  EXPECT_NE(error_of(TemplateModel::build(bad, {}, 60.0))
                .find("feature 1 of template frame 2 is not finite"),
            std::string::npos);
  bad(2, 1) = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(TemplateModel::build(bad, {}, 60.0).ok());

  EXPECT_NE(error_of(TemplateModel::build(ones(4, 3), {1}, 60.0)).find("start at state 0"),
            std::string::npos);
  EXPECT_NE(error_of(TemplateModel::build(ones(4, 3), {0, 2, 2}, 60.0)).find("strictly"),
            std::string::npos);
  EXPECT_NE(error_of(TemplateModel::build(ones(4, 3), {0, 3, 1}, 60.0)).find("strictly"),
            std::string::npos);
  EXPECT_NE(error_of(TemplateModel::build(ones(4, 3), {0, 4}, 60.0)).find("past the last"),
            std::string::npos);
  EXPECT_NE(error_of(TemplateModel::build(ones(4, 3), {}, 0.0)).find("frame rate"),
            std::string::npos);
  EXPECT_FALSE(TemplateModel::build(ones(4, 3), {}, -60.0).ok());
  EXPECT_FALSE(TemplateModel::build(ones(4, 3), {}, std::nan("")).ok());
  EXPECT_NE(error_of(TemplateModel::build(ones(4, 3), {}, 60.0, 4)).find("velocity_dims"),
            std::string::npos);
  EXPECT_FALSE(TemplateModel::build(ones(4, 3), {}, 60.0, -1).ok());
  EXPECT_EQ(TemplateModel::build(ones(4, 3), {}, 60.0, 3).value().velocity_dims(), 3);

  const std::vector<float> buffer(11, 0.0f);
  EXPECT_NE(error_of(TemplateModel::build(buffer, 4, 3, {}, 60.0)).find("expected 4 frames"),
            std::string::npos);
  EXPECT_FALSE(TemplateModel::build(buffer, 0, 3, {}, 60.0).ok());
  // Every message says where it comes from.
  EXPECT_EQ(error_of(TemplateModel::build(ones(4, 3), {}, 0.0)).rfind("template model: ", 0), 0u);
}

TEST(FollowParams, DefaultsAndPresetsAreValid) {
  EXPECT_TRUE(FollowParams{}.validate(10).ok());
  EXPECT_TRUE(FollowParams::paper().validate(10).ok());
  EXPECT_TRUE(FollowParams::left_to_right().validate(10).ok());
  EXPECT_FALSE(FollowParams::left_to_right().jump_enabled);
  EXPECT_FALSE(FollowParams::paper().tempo_adaptive);  // the paper's band is fixed
  EXPECT_TRUE(std::isinf(FollowParams::paper().limb_outlier_ratio));  // the plain Gaussian
  FollowParams uncapped;
  uncapped.velocity_distance_cap = std::numeric_limits<float>::infinity();
  EXPECT_TRUE(uncapped.validate(10).ok());
}

TEST(FollowParams, RejectsBadValues) {
  auto check = [](auto change, const char* what) {
    FollowParams p;
    change(p);
    Status status = p.validate(10);
    ASSERT_FALSE(status.ok()) << what;
    EXPECT_NE(status.error().message.find(what), std::string::npos) << status.error().message;
  };
  check([](FollowParams& p) { p.self_prob = -0.1f; }, "self_prob");
  check([](FollowParams& p) { p.next_prob = std::nanf(""); }, "next_prob");
  check([](FollowParams& p) { p.leave_prob = 1.5f; }, "leave_prob");
  check([](FollowParams& p) { p.pause_stay_prob = -1.0f; }, "pause_stay_prob");
  check([](FollowParams& p) { p.self_prob = p.next_prob = p.skip_prob = 0.0f; }, "skip_prob");
  check([](FollowParams& p) { p.emission_sigma = 0.0f; }, "emission_sigma");
  check([](FollowParams& p) { p.pause_distance_per_dim = -1.0f; }, "pause_distance_per_dim");
  check([](FollowParams& p) { p.lost_distance_per_dim = std::nanf(""); }, "lost_distance");
  check([](FollowParams& p) { p.confidence_window_frames = -1; }, "confidence_window");
  check([](FollowParams& p) { p.velocity_distance_cap = -0.1f; }, "velocity_distance_cap");
  check([](FollowParams& p) { p.limb_outlier_ratio = 0.5f; }, "limb_outlier_ratio");
  check([](FollowParams& p) { p.limb_outlier_floor = -1.0f; }, "limb_outlier_floor");
  check([](FollowParams& p) { p.tempo_time_constant_s = 0.0; }, "tempo_time_constant_s");
  check([](FollowParams& p) { p.max_tempo = 2.0f; }, "tempo range");
  check([](FollowParams& p) { p.min_tempo = 0.0f; }, "tempo range");
  check([](FollowParams& p) { p.tempo_hold_window_s = -0.1f; }, "tempo_hold_window_s");
  check([](FollowParams& p) { p.tempo_hold_window_s = std::nanf(""); }, "tempo_hold_window_s");
  check([](FollowParams& p) { p.tempo_hold_advance = 2.0f; }, "tempo_hold_advance");
  check([](FollowParams& p) { p.tempo_hold_max_s = -1.0f; }, "tempo_hold_max_s");
  check([](FollowParams& p) { p.skip_prob = 0.0f; }, "tempo_adaptive needs");
  check([](FollowParams& p) { p.max_steps_per_frame = 0; }, "max_steps_per_frame");
  check([](FollowParams& p) { p.jump_hold_s = -0.1f; }, "jump_hold_s");
  check([](FollowParams& p) { p.jump_hold_s = std::nanf(""); }, "jump_hold_s");
  check([](FollowParams& p) { p.jump_tolerance_frames = -1; }, "jump_tolerance_frames");
  check([](FollowParams& p) { p.resume_weights.assign(9, 1.0f); }, "resume_weights has 9");
  check([](FollowParams& p) { p.resume_weights.assign(10, 0.0f); }, "sum to zero");
  check(
      [](FollowParams& p) {
        p.resume_weights.assign(10, 1.0f);
        p.resume_weights[3] = -1.0f;
      },
      "resume_weights[3]");
}

TEST(FollowParams, TempoLimitsCarryEveryTempoField) {
  FollowParams params;
  params.tempo_time_constant_s = 1.5;
  params.min_tempo = 0.5f;
  params.max_tempo = 1.6f;
  params.tempo_hold_window_s = 0.2f;
  params.tempo_hold_advance = 0.25f;
  params.tempo_hold_max_s = 1.25f;
  const TempoLimits limits = params.tempo_limits(60.0);
  EXPECT_EQ(limits.time_constant_s, 1.5);
  EXPECT_EQ(limits.min_tempo, 0.5f);
  EXPECT_EQ(limits.max_tempo, 1.6f);
  EXPECT_EQ(limits.hold_window_s, double{0.2f});
  EXPECT_EQ(limits.hold_advance, 0.25f);
  EXPECT_EQ(limits.hold_max_s, double{1.25f});
  EXPECT_EQ(limits.template_fps, 60.0);
}

TEST(FollowParams, TrackersRefuseBadParameters) {
  const TemplateModel model = test::make_model({20}, 4, 1);
  FollowParams p;
  p.emission_sigma = -1.0f;
  EXPECT_FALSE(HmmFollower::create(model, p).ok());
  EXPECT_FALSE(NaiveHmmFollower::create(model, p).ok());
  OnlineDtwParams dtw;
  dtw.window_back = -1;
  EXPECT_FALSE(OnlineDtwTracker::create(model, dtw).ok());
}

TEST(FollowParams, PaperPresetRowsAreNormalised) {
  const TemplateModel model = test::make_model({10}, 4, 1);
  Result<HmmForward> forward = HmmForward::create(model, FollowParams::paper());
  ASSERT_TRUE(forward.ok());
  const HmmForward::Row row = forward.value().row(3);
  // self = next = 0.33, leave = 0.165, out of 0.825.
  EXPECT_NEAR(row.band[0], 0.4f, 1e-6f);
  EXPECT_NEAR(row.band[1], 0.4f, 1e-6f);
  EXPECT_EQ(row.band[2], 0.0f);
  EXPECT_NEAR(row.leave, 0.2f, 1e-6f);
  EXPECT_NEAR(forward.value().pause_stay(), 0.835f, 1e-6f);
  EXPECT_NEAR(forward.value().resume(0), 0.165f / 10.0f, 1e-7f);
}

TEST(FollowParams, EndOfTakeLeadsIntoThePauseState) {
  const TemplateModel model = test::make_model({5, 5}, 4, 1);
  const HmmForward forward = HmmForward::create(model, FollowParams{}).value();
  for (int j = 0; j < model.num_states(); ++j) {
    const HmmForward::Row r = forward.row(j);
    EXPECT_NEAR(r.band[0] + r.band[1] + r.band[2] + r.leave, 1.0f, 1e-6f) << j;
  }
  // The last frame of take 0 (state 4) cannot move into take 1 (state 5).
  EXPECT_EQ(forward.row(4).band[1], 0.0f);
  EXPECT_EQ(forward.row(4).band[2], 0.0f);
  EXPECT_EQ(forward.row(3).band[2], 0.0f);
  EXPECT_GT(forward.row(4).leave, forward.row(2).leave);

  // Without the jump the last frame keeps its mass.
  const HmmForward l2r = HmmForward::create(model, FollowParams::left_to_right()).value();
  EXPECT_EQ(l2r.row(4).band[0], 1.0f);
  EXPECT_EQ(l2r.row(4).leave, 0.0f);
  EXPECT_NEAR(l2r.row(3).band[0] + l2r.row(3).band[1], 1.0f, 1e-6f);
}

}  // namespace
}  // namespace duet
