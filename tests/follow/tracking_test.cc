// The follower (and its baselines) on synthetic performances whose true template position is
// known: exact replay, tempo changes, jumps within and across takes, a 30 Hz sensor.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "duet/follow/hmm_follower.h"
#include "duet/follow/naive_hmm.h"
#include "duet/follow/nearest_neighbour.h"
#include "duet/follow/online_dtw.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

constexpr int kDims = 60;

struct Frame {
  double position;  // true template position (global state index, fractional)
  double dt_s;
  bool jump = false;  // the performance jumped right before this frame
};

// Replays segments [from, from + length * speed) of the template, each at its own speed.
struct Segment {
  int from;
  int frames;  // input frames
  double speed = 1.0;
};

std::vector<Frame> perform(const std::vector<Segment>& segments, double dt_s, double fps = 60.0) {
  std::vector<Frame> frames;
  for (const Segment& s : segments) {
    for (int t = 0; t < s.frames; ++t) {
      frames.push_back({s.from + t * s.speed * dt_s * fps, dt_s, t == 0 && !frames.empty()});
    }
  }
  return frames;
}

struct Trace {
  std::vector<FollowResult> results;
  std::vector<int> truth;
};

Trace replay(Tracker& tracker, const TemplateModel& model, const std::vector<Frame>& frames,
             float noise = 0.0f, unsigned seed = 1) {
  std::mt19937 rng(seed);
  Trace out;
  tracker.reset();
  for (const Frame& f : frames) {
    std::vector<float> phi = test::features_at(model, f.position);
    if (noise > 0.0f) test::add_noise(phi, noise, rng);
    out.results.push_back(tracker.step(phi, f.dt_s));
    out.truth.push_back(static_cast<int>(std::lround(f.position)));
  }
  return out;
}

// Frames (after `skip`) whose estimate is more than `tolerance` frames from the truth.
int misses(const Trace& r, int tolerance, int skip = 3) {
  int n = 0;
  for (std::size_t t = static_cast<std::size_t>(skip); t < r.results.size(); ++t) {
    if (std::abs(r.results[t].state - r.truth[t]) > tolerance) ++n;
  }
  return n;
}

class TrackingTest : public ::testing::Test {
 protected:
  TemplateModel model_ = test::make_model({600}, kDims, 3);
};

TEST_F(TrackingTest, FollowsAnUnperturbedTemplateExactly) {
  const std::vector<Frame> frames = perform({{0, 599}}, 1.0 / 60);
  std::vector<std::unique_ptr<Tracker>> trackers;
  trackers.push_back(std::make_unique<HmmFollower>(HmmFollower::create(model_, {}).value()));
  trackers.push_back(std::make_unique<HmmFollower>(
      HmmFollower::create(model_, FollowParams::left_to_right()).value()));
  trackers.push_back(
      std::make_unique<NaiveHmmFollower>(NaiveHmmFollower::create(model_, {}).value()));
  trackers.push_back(std::make_unique<NearestNeighbourTracker>(
      NearestNeighbourTracker::create(model_, {}).value()));
  trackers.push_back(
      std::make_unique<OnlineDtwTracker>(OnlineDtwTracker::create(model_, {}).value()));
  for (const auto& tracker : trackers) {
    SCOPED_TRACE(tracker->name());
    const Trace r = replay(*tracker, model_, frames);
    EXPECT_EQ(misses(r, 0), 0);
    for (std::size_t t = 3; t < r.results.size(); ++t) {
      EXPECT_FALSE(r.results[t].jumped) << t;
      EXPECT_FALSE(r.results[t].lost) << t;
      EXPECT_FALSE(r.results[t].in_pause) << t;
      EXPECT_EQ(r.results[t].take, 0);
      EXPECT_EQ(r.results[t].frame_in_take, r.truth[t]);
    }
  }
}

TEST_F(TrackingTest, PaperPresetLagsByAtMostOneFrame) {
  // self = next and no skip: the band's prior advances half a frame per step, so at template
  // tempo the estimate may trail by one frame.
  HmmFollower paper = HmmFollower::create(model_, FollowParams::paper()).value();
  const Trace r = replay(paper, model_, perform({{0, 599}}, 1.0 / 60));
  EXPECT_EQ(misses(r, 1), 0);
}

TEST_F(TrackingTest, HmmIsConfidentOnAnExactReplay) {
  HmmFollower hmm = HmmFollower::create(model_, {}).value();
  const Trace r = replay(hmm, model_, perform({{0, 300}}, 1.0 / 60));
  for (std::size_t t = 3; t < r.results.size(); ++t) {
    EXPECT_GT(r.results[t].confidence, 0.9f) << t;
    EXPECT_TRUE(std::isfinite(r.results[t].log_likelihood));
  }
  EXPECT_TRUE(std::isfinite(hmm.context().total_log_likelihood()));
  EXPECT_EQ(hmm.context().frames(), 300);
}

TEST_F(TrackingTest, FollowsFasterAndSlowerReplaysWithNoise) {
  for (const double speed : {1.5, 0.7, 1.2}) {
    SCOPED_TRACE(speed);
    const int input_frames = static_cast<int>(590 / speed);
    const std::vector<Frame> frames = perform({{0, input_frames, speed}}, 1.0 / 60);
    HmmFollower hmm = HmmFollower::create(model_, {}).value();
    const Trace r = replay(hmm, model_, frames, 0.1f);
    EXPECT_EQ(misses(r, 1), 0);
    OnlineDtwTracker dtw = OnlineDtwTracker::create(model_, {}).value();
    EXPECT_LE(misses(replay(dtw, model_, frames, 0.1f), 2), input_frames / 50);
  }
}

// Mean of (estimate - truth) in frames after the first second: the lag (< 0) or lead (> 0).
double mean_offset(const Trace& r) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t t = 60; t < r.results.size(); ++t, ++n) sum += r.results[t].state - r.truth[t];
  return n > 0 ? sum / n : 0.0;
}

TEST_F(TrackingTest, TempoCentredBandRemovesTheLagOfAWeakEmission) {
  // A weak emission (large sigma, noisy input) leaves the band's prior to set the pace: a fixed
  // band, centred on the template's tempo, lags behind a fast dancer and runs ahead of a slow
  // one; the tempo-centred band learns the dancer's tempo and removes most of that offset.
  FollowParams adaptive;
  adaptive.emission_sigma = 4.0f;
  adaptive.pause_distance_per_dim = 50.0f;
  adaptive.lost_distance_per_dim = 1e9f;
  FollowParams fixed = adaptive;
  fixed.tempo_adaptive = false;
  for (const double speed : {1.5, 0.6}) {
    SCOPED_TRACE(speed);
    const std::vector<Frame> frames =
        perform({{0, static_cast<int>(590 / speed), speed}}, 1.0 / 60);
    HmmFollower with = HmmFollower::create(model_, adaptive).value();
    HmmFollower without = HmmFollower::create(model_, fixed).value();
    const Trace a = replay(with, model_, frames, 0.5f);
    const Trace f = replay(without, model_, frames, 0.5f);
    const double fixed_offset = mean_offset(f);
    const double adaptive_offset = mean_offset(a);
    EXPECT_GT(std::abs(fixed_offset), 2.0);  // the effect exists in this set-up
    EXPECT_LT(std::abs(adaptive_offset), 0.5 * std::abs(fixed_offset));
    EXPECT_NEAR(a.results.back().tempo, speed, 0.1);
    EXPECT_EQ(f.results.back().tempo, 1.0f);
  }
}

TEST_F(TrackingTest, AHeldPoseLeavesTheDancersTempo) {
  // 5 s of dance at the template's tempo from a 30 Hz sensor, a pose held for 0.6 s, the dance
  // again. The follower stands still through the hold; it is no slower dancer.
  const std::vector<Frame> frames =
      perform({{0, 150, 1.0}, {300, 18, 0.0}, {300, 60, 1.0}}, 1.0 / 30);
  FollowParams params;
  HmmFollower follower = HmmFollower::create(model_, params).value();
  const Trace trace = replay(follower, model_, frames);
  const std::size_t after_hold = 150 + 18;
  EXPECT_NEAR(trace.results[149].tempo, 1.0f, 0.02f);
  EXPECT_GT(trace.results[after_hold].tempo, 0.92f);
  EXPECT_EQ(misses(trace, 3), 0);

  // Every band move taught (0), the hold drags the tempo down.
  params.tempo_hold_window_s = 0.0f;
  HmmFollower dragged = HmmFollower::create(model_, params).value();
  const Trace slow = replay(dragged, model_, frames);
  EXPECT_LT(slow.results[after_hold].tempo, 0.85f);
}

TEST_F(TrackingTest, ASlowDancerOnAFastSensor) {
  // A learner at 0.7x on a 240 Hz suit: four steps a template frame of time, 0.175 template
  // frames a step. The tempo's range bounds the dancer's tempo; clamped per step (0.4, as at
  // 60 Hz) it held this dancer at 1.6x, and a weak emission let the estimate run ahead.
  FollowParams params;
  params.emission_sigma = 4.0f;
  params.pause_distance_per_dim = 50.0f;
  params.lost_distance_per_dim = 1e9f;
  const double speed = 0.7;
  const std::vector<Frame> frames =
      perform({{0, static_cast<int>(590 / speed * 4), speed}}, 1.0 / 240);
  HmmFollower hmm = HmmFollower::create(model_, params).value();
  const Trace r = replay(hmm, model_, frames, 0.5f);
  EXPECT_NEAR(r.results.back().tempo, speed, 0.1);
  EXPECT_LT(std::abs(mean_offset(r)), 1.0);  // 2.6 frames ahead when the range bounded a step
}

TEST(VelocityCap, LetsThePostureDecideWhileTheVelocitiesAreCorrupt) {
  // The last 6 of 60 dimensions are velocities. For 6 frames they are far off (a tracking glitch,
  // or the window after a dancer's jump): uncapped, they pull the estimate elsewhere; capped, the
  // posture keeps it where it is.
  const TemplateModel model = test::make_model({600}, kDims, 8, 60.0, 6);
  FollowParams capped;
  capped.velocity_distance_cap = 0.5f;
  // The cap alone: the outlier gate sets such a run aside too (FollowParams::outlier_max_s).
  capped.gate_outliers = false;
  FollowParams uncapped = capped;
  uncapped.velocity_distance_cap = std::numeric_limits<float>::infinity();
  HmmFollower with = HmmFollower::create(model, capped).value();
  HmmFollower without = HmmFollower::create(model, uncapped).value();
  int misses_with = 0, misses_without = 0;
  for (int t = 0; t < 400; ++t) {
    std::vector<float> phi = test::features_at(model, t);
    if (t >= 200 && t < 206) {
      for (int d = kDims - 6; d < kDims; ++d) phi[static_cast<std::size_t>(d)] += 8.0f;
    }
    const FollowResult a = with.step(phi, 1.0 / 60);
    const FollowResult b = without.step(phi, 1.0 / 60);
    if (t < 3) continue;
    misses_with += std::abs(a.state - t) > 1;
    misses_without += std::abs(b.state - t) > 1;
  }
  EXPECT_EQ(misses_with, 0);
  EXPECT_GE(misses_without, 3);
}

TEST_F(TrackingTest, ThirtyHertzInputAgainstSixtyHertzTemplate) {
  // dt = 1/30 applies the band twice per input frame; the dancer moves 2 template frames.
  for (const double speed : {1.0, 0.8, 1.3}) {
    SCOPED_TRACE(speed);
    const std::vector<Frame> frames =
        perform({{0, static_cast<int>(290 / speed), speed}}, 1.0 / 30);
    HmmFollower hmm = HmmFollower::create(model_, {}).value();
    const Trace r = replay(hmm, model_, frames, 0.1f);
    EXPECT_EQ(misses(r, 1), 0);
    for (std::size_t t = 1; t < r.results.size(); ++t) {
      EXPECT_EQ(r.results[t].steps, 2);
      if (t > 3) {
        EXPECT_FALSE(r.results[t].jumped) << t;
      }
    }
  }
}

TEST_F(TrackingTest, LateAndIrregularFrames) {
  // Input frames arrive with jittered intervals, some late by several template frames.
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> jitter(0.5, 1.5);
  std::vector<Frame> frames;
  double position = 0.0;
  for (int t = 0; t < 300 && position < 590; ++t) {
    const double dt = (t % 40 == 39 ? 5.0 : jitter(rng)) / 60.0;
    position += dt * 60.0;
    frames.push_back({position, dt});
  }
  HmmFollower hmm = HmmFollower::create(model_, {}).value();
  EXPECT_EQ(misses(replay(hmm, model_, frames, 0.05f), 1), 0);
}

TEST_F(TrackingTest, APlaceHeldForSecondsIsLostUntilTheDanceMovesOn) {
  // Two seconds of dance, the pose of frame 120 held still for 5 s (a person standing, a dance
  // stopped: it matches that frame exactly), then the dance again from there.
  const std::vector<Frame> frames = perform({{0, 120}, {120, 300, 0.0}, {120, 180}}, 1.0 / 60);
  const FollowParams params;
  ASSERT_FLOAT_EQ(params.held_place_lost_s, 3.0f);
  HmmFollower hmm = HmmFollower::create(model_, params).value();
  const Trace r = replay(hmm, model_, frames);
  for (std::size_t t = 3; t < r.results.size(); ++t) {
    const double held_s = t < 120 || t >= 420 ? 0.0 : (static_cast<double>(t) - 120.0) / 60.0;
    // Within a few frames of the hold's start and end: when the estimate settles is the HMM's.
    if (std::abs(held_s - 3.0) < 0.1 || (t >= 420 && t < 440)) continue;
    EXPECT_EQ(r.results[t].lost, held_s > 3.0) << t;
    EXPECT_EQ(r.results[t].held_still, held_s > 3.0) << t;         // and for that reason only
    EXPECT_LE(std::abs(r.results[t].state - r.truth[t]), 1) << t;  // the estimate itself holds
  }

  FollowParams never = params;
  never.held_place_lost_s = 0.0f;
  HmmFollower patient = HmmFollower::create(model_, never).value();
  const Trace held = replay(patient, model_, frames);
  for (std::size_t t = 3; t < held.results.size(); ++t) EXPECT_FALSE(held.results[t].lost) << t;
}

TEST_F(TrackingTest, APlaceFoundAgainAfterASpellLostIsLostUntilTheDanceMovesOn) {
  // Two seconds of dance, one second no frame explains (a wave), the pose of frame 120 held for
  // 1.5 s (the arm down: a person standing as a take's frame stands), then the dance from there.
  const FollowParams params;
  ASSERT_FLOAT_EQ(params.found_still_spell_s, 0.5f);
  const auto follow = [&](const FollowParams& p) {
    HmmFollower hmm = HmmFollower::create(model_, p).value();
    std::vector<FollowResult> results;
    for (int t = 0; t < 390; ++t) {
      const double position = t < 120 ? t : t < 270 ? 120.0 : 120.0 + (t - 270);
      std::vector<float> phi = test::features_at(model_, position);
      if (t >= 120 && t < 180) {
        for (float& v : phi) v += 3.0f;  // far from every frame
      }
      results.push_back(hmm.step(phi, 1.0 / 60));
    }
    return results;
  };
  const std::vector<FollowResult> r = follow(params);
  for (int t = 130; t < 180; ++t) EXPECT_TRUE(r[t].lost && !r[t].still_since_lost) << t;
  for (int t = 180; t < 270; ++t) {
    EXPECT_TRUE(r[t].lost) << t;  // the found again wait first (found_confirm_per_lost_s), then
    if (t >= 200) {               // the place found again that does not move on
      EXPECT_TRUE(r[t].still_since_lost && r[t].held_still) << t;
      EXPECT_LE(std::abs(r[t].state - 120), 3) << t;  // the estimate itself holds the place
    }
  }
  for (int t = 290; t < 390; ++t) {  // the dance moves on: followed
    EXPECT_FALSE(r[t].lost) << t;
    EXPECT_LE(std::abs(r[t].state - (120 + t - 270)), 1) << t;
  }

  FollowParams never = params;
  never.found_still_spell_s = 0.0f;
  const std::vector<FollowResult> found = follow(never);
  for (int t = 200; t < 390; ++t) EXPECT_FALSE(found[t].lost) << t;
}

TEST_F(TrackingTest, WithoutEvidenceTheTempoCarriesTheEstimateUntilItIsLost) {
  // Two seconds of dance, then four seconds with no evidence (a stalled sensor: FollowSession
  // gives the tracker missing frames) while the dancer dances on, then evidence again.
  const FollowParams params;
  ASSERT_FLOAT_EQ(params.missing_lost_s, 3.0f);
  HmmFollower hmm = HmmFollower::create(model_, params).value();
  const std::vector<float> none(kDims, std::numeric_limits<float>::quiet_NaN());
  float evidence_confidence = 0.0f;
  for (int t = 0; t < 500; ++t) {
    const bool missing = t >= 120 && t < 360;
    const FollowResult r = hmm.step(missing ? none : test::features_at(model_, t), 1.0 / 60);
    ASSERT_EQ(r.missing, missing) << t;
    const double missing_s = missing ? (t - 119) / 60.0 : 0.0;
    if (t < 3) continue;
    if (!missing) {
      if (t < 360 || t >= 380) {  // a few frames to be followed again after the spell lost
        EXPECT_FALSE(r.lost) << t;
        EXPECT_LE(std::abs(r.state - t), 1) << t;
      }
      evidence_confidence = r.confidence;
      continue;
    }
    EXPECT_LE(std::abs(r.state - t), 3) << t;  // the band moves on at the dancer's tempo
    if (std::abs(missing_s - 3.0) < 0.02) continue;
    EXPECT_EQ(r.lost, missing_s > 3.0) << t;
    // The last evidence's confidence stands, although the band spreads; lost, none.
    EXPECT_FLOAT_EQ(r.confidence, missing_s > 3.0 ? 0.0f : evidence_confidence) << t;
  }

  FollowParams never = params;
  never.missing_lost_s = 0.0f;
  HmmFollower patient = HmmFollower::create(model_, never).value();
  for (int t = 0; t < 360; ++t) {
    const bool missing = t >= 120;
    const FollowResult r = patient.step(missing ? none : test::features_at(model_, t), 1.0 / 60);
    if (t >= 3) {
      EXPECT_FALSE(r.lost) << t;
    }
  }
}

class LibraryTest : public ::testing::Test {
 protected:
  TemplateModel model_ = test::make_model({400, 300, 500}, kDims, 4);
  // Take 0 from its start, a jump into take 2, a jump back to another part of take 0, a jump to
  // take 1 at 1.3x, then a jump within take 1 backwards.
  std::vector<Frame> frames_ = perform(
      {{0, 120}, {700 + 250, 100}, {200, 90}, {400 + 20, 100, 1.3}, {400 + 60, 80}}, 1.0 / 60);
};

TEST_F(LibraryTest, RecoversAfterJumpsWithinAndAcrossTakes) {
  HmmFollower hmm = HmmFollower::create(model_, {}).value();
  const Trace r = replay(hmm, model_, frames_, 0.1f);
  int jumps = 0;
  for (std::size_t t = 0; t < frames_.size(); ++t) {
    if (!frames_[t].jump) continue;
    ++jumps;
    // Back on the right frame within 4 input frames, and it stays there.
    int recovered = -1;
    for (std::size_t k = t; k < t + 8 && k < frames_.size(); ++k) {
      if (std::abs(r.results[k].state - r.truth[k]) <= 1) {
        recovered = static_cast<int>(k - t);
        break;
      }
    }
    EXPECT_GE(recovered, 0) << "jump at frame " << t;
    EXPECT_LE(recovered, 4) << "jump at frame " << t;
    bool flagged = false;
    for (std::size_t k = t; k < t + 6; ++k) flagged = flagged || r.results[k].jumped;
    EXPECT_TRUE(flagged) << "jump at frame " << t;
    for (std::size_t k = t + 6; k < t + 60; ++k) {
      EXPECT_LE(std::abs(r.results[k].state - r.truth[k]), 1) << k;
      EXPECT_FALSE(r.results[k].jumped) << k;
      EXPECT_EQ(r.results[k].take, model_.take_of(r.truth[k])) << k;
    }
  }
  EXPECT_EQ(jumps, 4);
}

TEST_F(LibraryTest, PaperPresetAlsoRecovers) {
  HmmFollower hmm = HmmFollower::create(model_, FollowParams::paper()).value();
  const Trace r = replay(hmm, model_, frames_, 0.1f);
  // The paper has no skip transition, so the 1.3x segment is followed through self/next and
  // the jump; count frames far off rather than requiring +-1 everywhere.
  EXPECT_LE(misses(r, 3), 30);
}

TEST_F(LibraryTest, WithoutTheJumpTheLeftToRightHmmStaysInItsTake) {
  HmmFollower l2r = HmmFollower::create(model_, FollowParams::left_to_right()).value();
  const Trace r = replay(l2r, model_, frames_, 0.1f);
  // Tracks take 0 at first, then cannot reach take 2 after the jump.
  EXPECT_EQ(r.results[100].state, r.truth[100]);
  EXPECT_EQ(r.results[150].take, 0);
  EXPECT_FALSE(r.results[150].in_pause);
  // The naive O(M^2) forward without the jump behaves the same (with the emission's scale fixed,
  // as the naive forward has it: it estimates no sensor noise).
  FollowParams fixed = FollowParams::left_to_right();
  fixed.emission_noise_factor = 0.0f;
  HmmFollower fast = HmmFollower::create(model_, fixed).value();
  const Trace f = replay(fast, model_, frames_, 0.1f);
  NaiveHmmFollower naive = NaiveHmmFollower::create(model_, fixed).value();
  const Trace n = replay(naive, model_, frames_, 0.1f);
  for (std::size_t t = 0; t < frames_.size(); ++t)
    EXPECT_EQ(n.results[t].state, f.results[t].state);
}

TEST_F(LibraryTest, NearestNeighbourFollowsJumpsWithoutMemory) {
  NearestNeighbourTracker nn = NearestNeighbourTracker::create(model_, {}).value();
  const Trace r = replay(nn, model_, frames_, 0.02f);
  EXPECT_LE(misses(r, 1, 0), 5);
}

TEST_F(LibraryTest, ResetForgetsThePast) {
  HmmFollower hmm = HmmFollower::create(model_, {}).value();
  const Trace first = replay(hmm, model_, frames_, 0.1f);
  const Trace second = replay(hmm, model_, frames_, 0.1f);  // replay() resets first
  for (std::size_t t = 0; t < frames_.size(); ++t) {
    EXPECT_EQ(first.results[t].state, second.results[t].state);
    EXPECT_EQ(first.results[t].log_likelihood, second.results[t].log_likelihood);
  }
}

}  // namespace
}  // namespace duet
