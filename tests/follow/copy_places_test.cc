// CopyPlaces (issue 13): in a library grown with copies, each state's place in the captured
// takes, and a confidence window that counts every copy of a moment.
#include "duet/follow/copy_places.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "duet/follow/beam_follower.h"
#include "duet/follow/hmm_follower.h"
#include "duet/follow/synthetic_library.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

struct Grown {
  TemplateModel real = test::make_model({200, 150}, 12, 5);
  SyntheticLibraryOptions options = [] {
    SyntheticLibraryOptions o;
    o.num_states = 3000;
    o.keep_real_takes = true;
    return o;
  }();
  TemplateModel model = synthesize_library(real, options).value();
  std::vector<SyntheticTakeSource> sources = [this] {
    std::vector<SyntheticTakeSource> all = synthetic_take_sources(real, options).value();
    return std::vector<SyntheticTakeSource>(all.begin() + real.num_takes(), all.end());
  }();
};

TEST(CopyPlaces, EveryStateShowsItsCopiedFrame) {
  const Grown g;
  const CopyPlaces places = CopyPlaces::build(g.model, g.real.num_takes(), g.sources).value();
  ASSERT_EQ(places.num_states(), g.model.num_states());
  for (int state = 0; state < g.real.num_states(); ++state)
    EXPECT_EQ(places.place_of(state), state);
  for (int take = g.real.num_takes(); take < g.model.num_takes(); ++take) {
    const SyntheticTakeSource& source = g.sources[static_cast<std::size_t>(take - 2)];
    for (int state = g.model.take_begin(take); state < g.model.take_end(take); ++state) {
      const int frame = state - g.model.take_begin(take);
      EXPECT_EQ(places.place_of(state),
                g.real.take_begin(source.real_take) + source.real_frame(frame));
    }
  }
}

TEST(CopyPlaces, TheWindowCountsEveryCopyOfTheMomentAndOnlyThose) {
  const Grown g;
  const CopyPlaces places = CopyPlaces::build(g.model, g.real.num_takes(), g.sources).value();
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> mass(0.0f, 1.0f);
  std::vector<float> posterior(static_cast<std::size_t>(g.model.num_states()));
  for (float& p : posterior) p = mass(rng);
  std::vector<int> everything(posterior.size());
  for (int s = 0; s < g.model.num_states(); ++s) everything[static_cast<std::size_t>(s)] = s;
  for (const int state : {0, 5, 199, 200, 349, 1234, 2999}) {
    // By brute force: every state whose place is within 6 frames, in the same captured take.
    const int place = places.place_of(state);
    const int take = g.real.take_of(place);
    float expected = 0.0f;
    for (int s = 0; s < g.model.num_states(); ++s) {
      const int p = places.place_of(s);
      if (g.real.take_of(p) == take && std::abs(p - place) <= 6) expected += posterior[s];
    }
    EXPECT_NEAR(places.window_mass(posterior.data(), state, 6), expected, 1e-3f) << state;
    EXPECT_NEAR(places.window_mass(posterior.data(), state, 6, everything), expected, 1e-3f)
        << state;
  }
  // A support that leaves states out reads only those it lists.
  const std::vector<int> one = {1234};
  EXPECT_FLOAT_EQ(places.window_mass(posterior.data(), 1234, 6, one), posterior[1234]);
}

TEST(CopyPlaces, AGrownModelsConfidenceIsTheCapturedLibrarys) {
  // The same input followed through the captured takes and through a library of their copies at
  // speed 1 without noise (every moment held several times): the same confidence once the
  // window spans the copies, a split one without.
  const TemplateModel real = test::make_model({200, 150}, 12, 5);
  SyntheticLibraryOptions options;
  options.num_states = 350 * 4;
  options.keep_real_takes = true;
  options.min_speed = options.max_speed = 1.0f;
  options.noise = 0.0f;
  TemplateModel grown = synthesize_library(real, options).value();
  const std::vector<SyntheticTakeSource> all = synthetic_take_sources(real, options).value();
  const std::vector<SyntheticTakeSource> sources(all.begin() + 2, all.end());
  TemplateModel placed = grown;
  placed.set_copy_places(
      std::make_shared<const CopyPlaces>(CopyPlaces::build(placed, 2, sources).value()));
  FollowParams params;
  params.calibrate_confidence = false;  // the window mass itself
  HmmFollower captured = HmmFollower::create(real, params).value();
  HmmFollower split = HmmFollower::create(grown, params).value();
  HmmFollower counted = HmmFollower::create(placed, params).value();
  BeamFollower beam = BeamFollower::create(placed, params).value();  // reads its beam only
  std::mt19937 rng(8);
  for (int f = 0; f < 120; ++f) {
    std::vector<float> phi = test::features_at(real, 30.0 + f);
    test::add_noise(phi, 0.1f, rng);
    const FollowResult c = captured.step(phi, 1.0 / 60);
    const FollowResult s = split.step(phi, 1.0 / 60);
    const FollowResult p = counted.step(phi, 1.0 / 60);
    const FollowResult b = beam.step(phi, 1.0 / 60);
    EXPECT_NEAR(b.confidence, p.confidence, 1e-3f) << f;
    if (f < 10) continue;
    EXPECT_NEAR(p.confidence, c.confidence, 0.02f) << f;
    EXPECT_LT(s.confidence, 0.5f) << f;  // shared between four copies
  }
}

TEST(CopyPlaces, RejectsSourcesThatDoNotDescribeTheModel) {
  const Grown g;
  EXPECT_FALSE(CopyPlaces::build(g.model, 0, g.sources));
  EXPECT_FALSE(CopyPlaces::build(g.model, 2, std::span(g.sources).first(1)));
  std::vector<SyntheticTakeSource> wrong = g.sources;
  wrong[0].real_take = 7;
  Result<CopyPlaces> bad = CopyPlaces::build(g.model, 2, wrong);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("not a captured take"), std::string::npos);
}

}  // namespace
}  // namespace duet
