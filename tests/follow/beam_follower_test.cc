// The beam follower against the exact step on synthetic libraries: same states through jumps
// within and across takes, the pause state's mass accounted the same, full steps only where the
// beam may have lost the dancer, bad parameters rejected.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "duet/follow/beam_follower.h"
#include "duet/follow/hmm_follower.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

constexpr int kDims = 60;

// Template positions: segments {start, frames, speed}; a new segment is a jump.
struct Segment {
  double start;
  int frames;
  double speed = 1.0;
};

std::vector<std::vector<float>> perform(const TemplateModel& model,
                                        const std::vector<Segment>& segments, float noise) {
  std::mt19937 rng(3);
  std::vector<std::vector<float>> out;
  for (const Segment& s : segments) {
    for (int f = 0; f < s.frames; ++f) {
      std::vector<float> phi = test::features_at(model, s.start + f * s.speed);
      test::add_noise(phi, noise, rng);
      out.push_back(std::move(phi));
    }
  }
  return out;
}

class BeamTest : public ::testing::Test {
 protected:
  TemplateModel model_ = test::make_model({400, 300, 500}, kDims, 4, 60.0, 8);
  std::vector<std::vector<float>> inputs_ =
      perform(model_, {{0, 120}, {950, 100}, {200, 90}, {420, 100, 1.3}, {460, 80}}, 0.1f);
};

TEST_F(BeamTest, SameStatesAsTheExactStepThroughJumpsWithinAndAcrossTakes) {
  HmmFollower exact = HmmFollower::create(model_, {}).value();
  BeamFollower beam = BeamFollower::create(model_, {}).value();
  const int num_states = model_.num_states();
  int largest_beam = 0;
  for (std::size_t t = 0; t < inputs_.size(); ++t) {
    const FollowResult e = exact.step(inputs_[t], 1.0 / 60);
    const FollowResult b = beam.step(inputs_[t], 1.0 / 60);
    ASSERT_EQ(e.state, b.state) << "frame " << t;
    EXPECT_EQ(e.lost, b.lost) << "frame " << t;
    EXPECT_EQ(e.jumped, b.jumped) << "frame " << t;
    EXPECT_EQ(e.in_pause, b.in_pause) << "frame " << t;
    EXPECT_NEAR(e.confidence, b.confidence, 1e-3) << "frame " << t;
    EXPECT_NEAR(e.log_likelihood, b.log_likelihood, 1e-3 + 1e-4 * std::abs(e.log_likelihood))
        << "frame " << t;
    // The pause state's mass: the jump term of eq. 11 goes through it, kept exactly.
    const float pause_e = exact.context().alpha()[static_cast<std::size_t>(num_states)];
    const float pause_b = beam.context().alpha()[static_cast<std::size_t>(num_states)];
    EXPECT_NEAR(pause_e, pause_b, 1e-6f + 1e-3f * pause_e) << "frame " << t;
    double total = 0.0;
    for (const float a : beam.context().alpha()) total += a;
    EXPECT_NEAR(total, 1.0, 1e-5) << "frame " << t;
    largest_beam = std::max(largest_beam, beam.context().beam_size());
  }
  // The beam did the work: a handful of states, the full step on few frames.
  EXPECT_LT(largest_beam, num_states / 10);
  EXPECT_LT(beam.context().full_steps() * 20, beam.context().frames());
}

TEST_F(BeamTest, MissingAndSlowFramesAsTheExactStep) {
  HmmFollower exact = HmmFollower::create(model_, {}).value();
  BeamFollower beam = BeamFollower::create(model_, {}).value();
  const std::vector<float> missing(kDims, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t t = 0; t < inputs_.size(); ++t) {
    const bool gap = t % 50 >= 45;  // 5 missing frames in every 50
    const double dt = t % 7 == 0 ? 1.0 / 30 : 1.0 / 60;
    const FollowResult e = exact.step(gap ? missing : inputs_[t], dt);
    const FollowResult b = beam.step(gap ? missing : inputs_[t], dt);
    ASSERT_EQ(e.state, b.state) << "frame " << t;
    EXPECT_EQ(e.missing, b.missing);
    EXPECT_EQ(e.lost, b.lost) << "frame " << t;
  }
}

TEST_F(BeamTest, AFarDancerTakesTheFullStepAndIsFoundAgain) {
  BeamFollower beam = BeamFollower::create(model_, {}).value();
  HmmFollower exact = HmmFollower::create(model_, {}).value();
  for (int t = 0; t < 60; ++t) {
    beam.step(inputs_[static_cast<std::size_t>(t)], 1.0 / 60);
    exact.step(inputs_[static_cast<std::size_t>(t)], 1.0 / 60);
  }
  // Every state is about as far: any of those the index left out could hold the maximum.
  const long long full_before = beam.context().full_steps();
  const std::vector<float> far(kDims, 50.0f);
  for (int t = 0; t < 5; ++t) {
    const FollowResult b = beam.step(far, 1.0 / 60);
    const FollowResult e = exact.step(far, 1.0 / 60);
    EXPECT_TRUE(b.lost);
    EXPECT_EQ(b.state, e.state);
    EXPECT_TRUE(std::isfinite(b.log_likelihood));
  }
  EXPECT_GT(beam.context().full_steps(), full_before);
  // Back on the template: the jump candidates find the dancer again, as the exact step does.
  for (int t = 60; t < 120; ++t) {
    const FollowResult b = beam.step(inputs_[static_cast<std::size_t>(t)], 1.0 / 60);
    const FollowResult e = exact.step(inputs_[static_cast<std::size_t>(t)], 1.0 / 60);
    EXPECT_EQ(b.state, e.state) << "frame " << t;
  }
  EXPECT_GT(beam.context().beam_size(), 0);
}

TEST_F(BeamTest, ALostSpellTakesTheFullStepOncePerIntervalAndIsFoundAgainAtOnce) {
  // Four seconds far from every state: lost on every frame; once lost for
  // BeamParams::lost_spell_before_s (2 s), the full step (every state's emission) only once per
  // lost_full_step_s (0.5 s), not on every frame as when exact.
  BeamParams every_frame;
  every_frame.lost_full_step_s = 0.0;
  BeamFollower spaced = BeamFollower::create(model_, {}).value();
  BeamFollower exact_beam = BeamFollower::create(model_, {}, every_frame).value();
  HmmFollower exact = HmmFollower::create(model_, {}).value();
  for (std::size_t t = 0; t < 60; ++t) {
    spaced.step(inputs_[t], 1.0 / 60);
    exact_beam.step(inputs_[t], 1.0 / 60);
    exact.step(inputs_[t], 1.0 / 60);
  }
  const long long spaced_before = spaced.context().full_steps();
  const long long exact_before = exact_beam.context().full_steps();
  const std::vector<float> far(kDims, 50.0f);
  constexpr int kFarFrames = 240;
  long long spaced_at_3s = 0;
  for (int t = 0; t < kFarFrames; ++t) {
    if (t == 180) spaced_at_3s = spaced.context().full_steps();
    const FollowResult s = spaced.step(far, 1.0 / 60);
    const FollowResult e = exact.step(far, 1.0 / 60);
    exact_beam.step(far, 1.0 / 60);
    EXPECT_EQ(s.lost, e.lost) << "far frame " << t;
    EXPECT_TRUE(std::isfinite(s.confidence) && std::isfinite(s.log_likelihood));
  }
  EXPECT_GE(exact_beam.context().full_steps() - exact_before, kFarFrames - 4);
  EXPECT_GE(spaced_at_3s - spaced_before, 100) << "exact for the first 2 s";
  EXPECT_LE(spaced.context().full_steps() - spaced_at_3s, 3) << "one per 0.5 s in the last 1 s";
  // Back on the template: the first frames find the dancer as the exact step does.
  int differing = 0;
  for (std::size_t t = 60; t < 200; ++t) {
    const FollowResult s = spaced.step(inputs_[t], 1.0 / 60);
    exact_beam.step(inputs_[t], 1.0 / 60);
    const FollowResult e = exact.step(inputs_[t], 1.0 / 60);
    if (t >= 63) {
      EXPECT_EQ(s.state, e.state) << "frame " << t;
      EXPECT_EQ(s.lost, e.lost) << "frame " << t;
    }
    differing += s.state != e.state ? 1 : 0;
  }
  EXPECT_LE(differing, 3);
}

TEST_F(BeamTest, ABeamTooWideFallsBackToTheFullStepWithTheSameStates) {
  HmmFollower exact = HmmFollower::create(model_, {}).value();
  BeamParams narrow;
  narrow.max_states = 1;  // every beam is too wide: the full step on every frame
  narrow.lost_full_step_s = 0.0;  // even while lost
  BeamFollower beam = BeamFollower::create(model_, {}, narrow).value();
  for (std::size_t t = 0; t < inputs_.size(); ++t) {
    ASSERT_EQ(exact.step(inputs_[t], 1.0 / 60).state, beam.step(inputs_[t], 1.0 / 60).state)
        << "frame " << t;
  }
  EXPECT_GT(beam.context().full_steps() * 2, beam.context().frames());
}

TEST_F(BeamTest, ALongGapWidensTheBeamIntoAFullStepAndTheEstimatesAreTheSameAfterIt) {
  HmmFollower exact = HmmFollower::create(model_, {}).value();
  BeamParams small;
  small.max_states = 32;
  BeamFollower beam = BeamFollower::create(model_, {}, small).value();
  const std::vector<float> missing(kDims, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t t = 0; t < 60; ++t) {
    ASSERT_EQ(exact.step(inputs_[t], 1.0 / 60).state, beam.step(inputs_[t], 1.0 / 60).state);
  }
  const long long full_before = beam.context().full_steps();
  for (int t = 0; t < 40; ++t) {  // 40 frames of 8 template steps with no evidence
    // The mass spreads until the posterior is nearly flat (its maximum then is float noise, in
    // the exact step as in the beam): only the flags are compared.
    const FollowResult e = exact.step(missing, 8.0 / 60);
    const FollowResult b = beam.step(missing, 8.0 / 60);
    EXPECT_TRUE(e.missing && b.missing);
    EXPECT_EQ(e.lost, b.lost);
  }
  EXPECT_GT(beam.context().full_steps(), full_before);
  for (std::size_t t = 60; t < 200; ++t) {
    ASSERT_EQ(exact.step(inputs_[t], 1.0 / 60).state, beam.step(inputs_[t], 1.0 / 60).state)
        << "frame " << t;
  }
}

TEST_F(BeamTest, StatesWithinTheSettlingBoundSpareFullStepsAndKeepTheExactStates) {
  // One nearest candidate leaves most frames uncertain; the states within the bound that settles
  // the frame (a radius search) finish them sparsely. With room for a single such state the radius
  // search overflows and the full step does it: the same states, more full steps.
  BeamParams few;
  few.jump_candidates = 1;
  few.wide_jump_candidates = 1;
  BeamParams no_radius = few;
  no_radius.radius_candidates = 1;
  HmmFollower exact = HmmFollower::create(model_, {}).value();
  BeamFollower with_radius = BeamFollower::create(model_, {}, few).value();
  BeamFollower without = BeamFollower::create(model_, {}, no_radius).value();
  for (std::size_t t = 0; t < inputs_.size(); ++t) {
    const FollowResult e = exact.step(inputs_[t], 1.0 / 60);
    const FollowResult r = with_radius.step(inputs_[t], 1.0 / 60);
    ASSERT_EQ(e.state, r.state) << "frame " << t;
    EXPECT_EQ(e.lost, r.lost) << "frame " << t;
    EXPECT_EQ(e.in_pause, r.in_pause) << "frame " << t;
    EXPECT_NEAR(e.confidence, r.confidence, 1e-3) << "frame " << t;
    ASSERT_EQ(e.state, without.step(inputs_[t], 1.0 / 60).state) << "frame " << t;
  }
  EXPECT_LT(with_radius.context().full_steps() * 2, without.context().full_steps());
}

TEST_F(BeamTest, PaperPresetAsTheExactStep) {
  const FollowParams paper = FollowParams::paper();
  HmmFollower exact = HmmFollower::create(model_, paper).value();
  BeamFollower beam = BeamFollower::create(model_, paper, BeamParams::suited_to(paper)).value();
  EXPECT_EQ(BeamParams::suited_to(paper).prune_ratio, 1e-20f);
  for (std::size_t t = 0; t < inputs_.size(); ++t) {
    ASSERT_EQ(exact.step(inputs_[t], 1.0 / 60).state, beam.step(inputs_[t], 1.0 / 60).state)
        << "frame " << t;
  }
}

TEST_F(BeamTest, RejectsTheLeftToRightHmm) {
  Result<BeamFollower> beam = BeamFollower::create(model_, FollowParams::left_to_right());
  ASSERT_FALSE(beam);
  EXPECT_NE(beam.error().message.find("pause state"), std::string::npos);
}

TEST(BeamParamsTest, RejectsBadParameters) {
  const TemplateModel model = test::make_model({100}, 8, 1);
  BeamParams bad;
  bad.jump_candidates = 0;
  Result<BeamFollower> none = BeamFollower::create(model, {}, bad);
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message.find("jump_candidates"), std::string::npos);
  bad = BeamParams{};
  bad.radius_candidates = bad.wide_jump_candidates - 1;
  Result<BeamFollower> small_radius = BeamFollower::create(model, {}, bad);
  ASSERT_FALSE(small_radius);
  EXPECT_NE(small_radius.error().message.find("radius_candidates"), std::string::npos);
  bad = BeamParams{};
  bad.prune_ratio = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(BeamFollower::create(model, {}, bad));
  bad = BeamParams{};
  bad.deep_prune_ratio = 1.0f;
  Result<BeamFollower> unsettled = BeamFollower::create(model, {}, bad);
  ASSERT_FALSE(unsettled);
  EXPECT_NE(unsettled.error().message.find("deep_prune_ratio"), std::string::npos);
  bad = BeamParams{};
  bad.well_fitting_ratio = 0.5f;
  Result<BeamFollower> below_one = BeamFollower::create(model, {}, bad);
  ASSERT_FALSE(below_one);
  EXPECT_NE(below_one.error().message.find("well_fitting_ratio"), std::string::npos);
  bad = BeamParams{};
  bad.well_fitting_states = -1;
  EXPECT_FALSE(BeamFollower::create(model, {}, bad));
  bad = BeamParams{};
  bad.lost_full_step_s = -1.0;
  Result<BeamFollower> negative = BeamFollower::create(model, {}, bad);
  ASSERT_FALSE(negative);
  EXPECT_NE(negative.error().message.find("lost_full_step_s"), std::string::npos);
  // A model of velocities alone has no posture for the index.
  const TemplateModel velocities = test::make_model({100}, 8, 1, 60.0, 8);
  Result<BeamFollower> no_posture = BeamFollower::create(velocities, {});
  ASSERT_FALSE(no_posture);
  EXPECT_NE(no_posture.error().message.find("posture"), std::string::npos);
}

}  // namespace
}  // namespace duet
