// The forward step never underflows to zeros or NaN: long inputs, missing frames, zeros, a frozen
// user, features far from every template frame, a very sharp emission.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "duet/follow/hmm_follower.h"
#include "duet/follow/nearest_neighbour.h"
#include "duet/follow/online_dtw.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

constexpr int kDims = 60;
constexpr double kDt = 1.0 / 60;
const float kNaN = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();

// alpha is a probability distribution: finite, non-negative, sums to 1.
void expect_valid_alpha(const HmmFollower& hmm) {
  double sum = 0.0;
  for (const float a : hmm.context().alpha()) {
    ASSERT_TRUE(std::isfinite(a));
    ASSERT_GE(a, 0.0f);
    sum += a;
  }
  ASSERT_NEAR(sum, 1.0, 1e-4);
}

void expect_valid_result(const FollowResult& r, const TemplateModel& model) {
  ASSERT_GE(r.state, 0);
  ASSERT_LT(r.state, model.num_states());
  ASSERT_EQ(r.take, model.take_of(r.state));
  ASSERT_TRUE(std::isfinite(r.confidence));
  ASSERT_GE(r.confidence, 0.0f);
  ASSERT_LE(r.confidence, 1.0f);
  ASSERT_TRUE(std::isfinite(r.log_likelihood));
  ASSERT_FALSE(std::isnan(r.best_distance_per_dim));
}

class RobustnessTest : public ::testing::Test {
 protected:
  TemplateModel model_ = test::make_model({500, 500}, kDims, 8);
  std::vector<float> template_frame(int i) { return test::features_at(model_, i); }
  // Replays frames [from, from + count) and checks they are followed exactly (after 3 frames to
  // settle), so the tests start from a confident state.
  void track(HmmFollower& hmm, int from, int count) {
    for (int i = from; i < from + count; ++i) {
      const FollowResult r = hmm.step(template_frame(i), kDt);
      if (i - from >= 3) {
        ASSERT_EQ(r.state, i);
      }
    }
  }
};

TEST_F(RobustnessTest, HundredThousandFrames) {
  HmmFollower hmm = HmmFollower::create(model_, {}).value();
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> anywhere(0, model_.num_states() - 1);
  std::uniform_real_distribution<double> speed(0.7, 1.4);
  double position = 0.0;
  for (int t = 0; t < 100000; ++t) {
    if (t % 500 == 0) position = anywhere(rng);
    std::vector<float> phi = test::features_at(model_, position);
    test::add_noise(phi, 0.2f, rng);
    if (t % 101 == 0) phi.assign(phi.size(), kNaN);
    if (t % 997 == 0) phi.assign(phi.size(), 0.0f);
    position += speed(rng);
    if (position >= model_.num_states() - 1) position = 0.0;
    const FollowResult r = hmm.step(phi, kDt);
    expect_valid_result(r, model_);
    if (t % 1000 == 0) expect_valid_alpha(hmm);
  }
  expect_valid_alpha(hmm);
  EXPECT_TRUE(std::isfinite(hmm.context().total_log_likelihood()));
  EXPECT_EQ(hmm.context().frames(), 100000);
}

TEST_F(RobustnessTest, MissingFramesAreFlaggedAndDoNotPoisonTheState) {
  HmmFollower hmm = HmmFollower::create(model_, {}).value();
  track(hmm, 0, 100);
  for (int k = 0; k < 50; ++k) {
    std::vector<float> phi = template_frame(100 + k);
    if (k % 2 == 0) {
      phi.assign(phi.size(), kNaN);
    } else {
      phi[static_cast<std::size_t>(k)] = k % 4 == 1 ? kInf : -kInf;
    }
    const FollowResult r = hmm.step(phi, kDt);
    EXPECT_TRUE(r.missing);
    EXPECT_EQ(r.log_likelihood, 0.0);
    EXPECT_FALSE(r.lost);
    expect_valid_result(r, model_);
    expect_valid_alpha(hmm);
  }
  // The band kept moving the mass forward; real frames snap it back at once.
  const FollowResult r = hmm.step(template_frame(150), kDt);
  EXPECT_FALSE(r.missing);
  EXPECT_LE(std::abs(r.state - 150), 1);
  track(hmm, 151, 20);
}

// A frame with some dimensions NaN (a controller out of the headset's view, FollowSession) is
// evidence on the others: the unobserved ones are carried along the dance from the last followed
// estimate. A dancer speeding up to 1.5x while a third of the dimensions are unseen is followed by
// the rest, not held to the carried tempo. Before any frame was followed nothing can be carried:
// such a frame is missing; so is one with an infinity (a broken frame, not an unseen part).
TEST_F(RobustnessTest, PartlyObservedFramesAreEvidenceOnTheRest) {
  HmmFollower hmm = HmmFollower::create(model_, {}).value();
  std::vector<float> first = template_frame(0);
  first[0] = kNaN;
  EXPECT_TRUE(hmm.step(first, kDt).missing);
  hmm.reset();
  track(hmm, 0, 100);
  double position = 100.0;
  for (int k = 0; k < 60; ++k, position += 1.5) {
    std::vector<float> phi = test::features_at(model_, position);
    for (int d = 0; d < kDims / 3; ++d) phi[static_cast<std::size_t>(d)] = kNaN;
    const FollowResult r = hmm.step(phi, kDt);
    EXPECT_TRUE(r.partly_observed);
    EXPECT_FALSE(r.missing);
    EXPECT_NE(r.log_likelihood, 0.0);
    expect_valid_result(r, model_);
    expect_valid_alpha(hmm);
    if (k >= 10) {
      EXPECT_LE(std::abs(r.state - position), 2.0) << "frame " << k;
    }
  }
  std::vector<float> broken = test::features_at(model_, position);
  broken[0] = kNaN;
  broken[1] = kInf;
  const FollowResult r = hmm.step(broken, kDt);
  EXPECT_TRUE(r.missing);
  EXPECT_FALSE(r.partly_observed);
}

TEST_F(RobustnessTest, FramesOfZeros) {
  HmmFollower hmm = HmmFollower::create(model_, {}).value();
  track(hmm, 200, 20);
  const std::vector<float> zeros(kDims, 0.0f);
  for (int t = 0; t < 2000; ++t) expect_valid_result(hmm.step(zeros, kDt), model_);
  expect_valid_alpha(hmm);
  hmm.step(template_frame(700), kDt);
  hmm.step(template_frame(701), kDt);
  EXPECT_EQ(hmm.step(template_frame(702), kDt).state, 702);
}

TEST_F(RobustnessTest, FrozenUser) {
  HmmFollower hmm = HmmFollower::create(model_, {}).value();
  track(hmm, 280, 20);
  const std::vector<float> frozen = template_frame(300);
  FollowResult r;
  for (int t = 0; t < 5000; ++t) {
    r = hmm.step(frozen, kDt);
    expect_valid_result(r, model_);
  }
  expect_valid_alpha(hmm);
  // The self transition holds the estimate near the frozen frame, and a place held that long
  // (83 s) is no dance: lost (FollowParams::held_place_lost_s).
  EXPECT_LE(std::abs(r.state - 300), 3);
  EXPECT_TRUE(r.lost);
  EXPECT_TRUE(std::isfinite(hmm.context().total_log_likelihood()));
}

TEST_F(RobustnessTest, FeaturesFarFromEveryTemplateFrame) {
  for (const float far : {30.0f, 1e3f, 1e20f, -1e30f, FLT_MAX, -FLT_MAX}) {
    SCOPED_TRACE(far);
    HmmFollower hmm = HmmFollower::create(model_, {}).value();
    track(hmm, 600, 20);
    std::vector<float> phi(kDims, far);
    phi[0] = -far;  // not all equal, so no accidental symmetry
    for (int t = 0; t < 300; ++t) {
      const FollowResult r = hmm.step(phi, kDt);
      expect_valid_result(r, model_);
      EXPECT_TRUE(r.lost) << t;
      EXPECT_FALSE(r.missing);
    }
    expect_valid_alpha(hmm);
    // Back to the template: the estimate is there within a few frames, and after 5 s lost it is
    // reported followed once the input has held it for found_confirm_max_s (0.75 s: 45 frames).
    FollowResult r;
    for (int i = 100; i < 106; ++i) r = hmm.step(template_frame(i), kDt);
    EXPECT_EQ(r.state, 105);
    EXPECT_TRUE(r.lost);
    for (int i = 106; i < 144; ++i) r = hmm.step(template_frame(i), kDt);
    EXPECT_EQ(r.state, 143);
    EXPECT_TRUE(r.lost);
    for (int i = 144; i < 146; ++i) r = hmm.step(template_frame(i), kDt);
    EXPECT_EQ(r.state, 145);
    EXPECT_FALSE(r.lost);
  }
}

TEST_F(RobustnessTest, OutlierFramesAreSetAsideForOutlierMaxSThenAreEvidence) {
  std::vector<float> outlier(kDims, 30.0f);
  outlier[0] = -30.0f;
  {
    // One outlier while followed: transitions only, the estimate moves on along the band, no
    // pause, no jump; the next frames are followed as before.
    HmmFollower hmm = HmmFollower::create(model_, {}).value();
    track(hmm, 0, 100);
    const FollowResult r = hmm.step(outlier, kDt);
    EXPECT_TRUE(r.outlier);
    EXPECT_TRUE(r.lost);  // nothing explains it
    EXPECT_FALSE(r.in_pause);
    EXPECT_FALSE(r.jumped);
    EXPECT_LE(std::abs(r.state - 100), 2);
    EXPECT_EQ(r.log_likelihood, 0.0);
    expect_valid_alpha(hmm);
    const FollowResult next = hmm.step(template_frame(101), kDt);
    EXPECT_FALSE(next.outlier);
    EXPECT_FALSE(next.lost);
    EXPECT_FALSE(next.jumped);
    EXPECT_EQ(next.state, 101);
    track(hmm, 102, 10);
  }
  {
    // A tracker's pop of three frames: each is set aside, the estimate moves on along the band,
    // and the dance is followed on after it with no jump.
    HmmFollower hmm = HmmFollower::create(model_, {}).value();
    track(hmm, 0, 100);
    for (int k = 0; k < 3; ++k) {
      const FollowResult r = hmm.step(outlier, kDt);
      EXPECT_TRUE(r.outlier) << k;
      EXPECT_FALSE(r.in_pause) << k;
      EXPECT_FALSE(r.jumped) << k;
    }
    FollowResult r;
    for (int i = 104; i < 110; ++i) {
      r = hmm.step(template_frame(i), kDt);
      EXPECT_FALSE(r.jumped) << i;
    }
    EXPECT_EQ(r.state, 109);
    EXPECT_FALSE(r.lost);
  }
  {
    // A run is set aside for outlier_max_s (0.1 s: 6 frames at 60 Hz); the next frame is evidence:
    // the dancer really left the library, and the pause state takes the mass.
    const FollowParams params;
    ASSERT_FLOAT_EQ(params.outlier_max_s, 0.1f);
    HmmFollower hmm = HmmFollower::create(model_, params).value();
    track(hmm, 0, 100);
    for (int k = 0; k < 6; ++k) EXPECT_TRUE(hmm.step(outlier, kDt).outlier) << k;
    const FollowResult seventh = hmm.step(outlier, kDt);
    EXPECT_FALSE(seventh.outlier);
    EXPECT_TRUE(seventh.in_pause);
    EXPECT_TRUE(seventh.lost);
  }
  {
    // outlier_max_s 0: one frame only, the second in a row is evidence.
    FollowParams params;
    params.outlier_max_s = 0.0f;
    HmmFollower hmm = HmmFollower::create(model_, params).value();
    track(hmm, 0, 100);
    EXPECT_TRUE(hmm.step(outlier, kDt).outlier);
    const FollowResult second = hmm.step(outlier, kDt);
    EXPECT_FALSE(second.outlier);
    EXPECT_TRUE(second.in_pause);
  }
  {
    // Without the gate the first one already hands the pause state the mass.
    FollowParams params;
    params.gate_outliers = false;
    HmmFollower hmm = HmmFollower::create(model_, params).value();
    track(hmm, 0, 100);
    const FollowResult r = hmm.step(outlier, kDt);
    EXPECT_FALSE(r.outlier);
    EXPECT_TRUE(r.in_pause);
  }
  {
    // A frame another place explains (the dancer jumped) is never an outlier: evidence at once.
    HmmFollower hmm = HmmFollower::create(model_, {}).value();
    track(hmm, 0, 100);
    FollowResult r;
    for (int i = 700; i < 703; ++i) {
      r = hmm.step(template_frame(i), kDt);
      EXPECT_FALSE(r.outlier) << i;
    }
    EXPECT_EQ(r.state, 702);
  }
}

TEST_F(RobustnessTest, BetweenPlacesAfterAJumpIsNotLostUnlessThePaperReadingIsAsked) {
  // Lost means that no template frame explains the input (issue 11). Right after a jump the pause
  // state holds the mass while the new place gathers evidence, though that place explains the
  // input exactly: in_pause, not lost. pause_reported_lost (the paper preset) reports it lost.
  for (const bool paper_reading : {false, true}) {
    SCOPED_TRACE(paper_reading ? "pause reported lost" : "default");
    FollowParams params;
    params.pause_reported_lost = paper_reading;
    HmmFollower hmm = HmmFollower::create(model_, params).value();
    track(hmm, 0, 100);
    int between = 0;
    FollowResult r;
    for (int i = 700; i < 720; ++i) {
      r = hmm.step(template_frame(i), kDt);
      EXPECT_LT(r.best_distance_per_dim, 1e-6f) << i;
      between += r.in_pause ? 1 : 0;
      EXPECT_EQ(r.lost, paper_reading && r.in_pause) << i;
    }
    EXPECT_GE(between, 1);
    EXPECT_EQ(r.state, 719);
  }
}

TEST_F(RobustnessTest, SharpEmissionAndDistantPauseNeverUnderflow) {
  // sigma = 0.05 puts log-emissions of other frames around -1e4: exp underflows for everything
  // but the best frame, and the pause emission underflows entirely.
  FollowParams params;
  params.emission_sigma = 0.05f;
  params.pause_distance_per_dim = 50.0f;
  HmmFollower hmm = HmmFollower::create(model_, params).value();
  std::mt19937 rng(3);
  for (int t = 0; t < 3000; ++t) {
    // Jumps every 100 frames: the predicted mass sits where the emissions are ~exp(-1e4).
    std::vector<float> phi = template_frame((t / 100) * 317 % 900 + t % 100);
    test::add_noise(phi, 0.3f, rng);
    const FollowResult r = hmm.step(phi, kDt);
    expect_valid_result(r, model_);
  }
  expect_valid_alpha(hmm);
}

TEST_F(RobustnessTest, BaselinesStayFiniteToo) {
  NearestNeighbourTracker nn = NearestNeighbourTracker::create(model_, {}).value();
  OnlineDtwTracker dtw = OnlineDtwTracker::create(model_, {}).value();
  std::vector<Tracker*> trackers = {&nn, &dtw};
  for (Tracker* tracker : trackers) {
    SCOPED_TRACE(tracker->name());
    for (int t = 0; t < 3000; ++t) {
      std::vector<float> phi = template_frame(t % 1000);
      if (t % 7 == 0) phi.assign(phi.size(), kNaN);
      if (t % 11 == 0) phi.assign(phi.size(), 1e30f);
      if (t % 13 == 0) phi.assign(phi.size(), 0.0f);
      const FollowResult r = tracker->step(phi, t % 5 == 0 ? 1.0 / 30 : kDt);
      if (t > 0) expect_valid_result(r, model_);
    }
  }
}

}  // namespace
}  // namespace duet
