// The synthetic library generator (scale tests of issue 13): the asked size, copies of the real
// takes at the asked speeds, reproducible, bad options rejected.
#include <gtest/gtest.h>

#include "duet/follow/synthetic_library.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

TEST(SyntheticLibrary, CopiesTheTakesUntilTheAskedSize) {
  const TemplateModel real = test::make_model({200, 150}, 12, 5, 60.0, 4);
  SyntheticLibraryOptions options;
  options.num_states = 1000;
  options.min_speed = options.max_speed = 1.0f;
  options.noise = 0.0f;
  const TemplateModel big = synthesize_library(real, options).value();
  EXPECT_EQ(big.num_states(), 1000);
  EXPECT_EQ(big.num_dims(), 12);
  EXPECT_EQ(big.velocity_dims(), 4);
  EXPECT_EQ(big.frame_rate_hz(), 60.0);
  // At speed 1 without noise the copies are the takes, in turn.
  EXPECT_EQ(big.take_begin(1), 200);
  EXPECT_EQ(big.take_begin(2), 350);
  EXPECT_TRUE(big.features().middleRows(350, 200).isApprox(real.features().topRows(200)));
  EXPECT_TRUE(big.features().middleRows(200, 150).isApprox(real.features().middleRows(200, 150)));
}

TEST(SyntheticLibrary, WarpsTimeAndAddsNoise) {
  const TemplateModel real = test::make_model({200, 150}, 12, 5, 60.0, 4);
  SyntheticLibraryOptions options;
  options.num_states = 5000;
  const TemplateModel big = synthesize_library(real, options).value();
  ASSERT_EQ(big.num_states(), 5000);
  int shorter = 0, longer = 0;
  for (int k = 0; k + 1 < big.num_takes(); ++k) {  // the last copy may be cut short
    const int length = big.take_end(k) - big.take_begin(k);
    const int source = real.take_end(k % 2) - real.take_begin(k % 2);
    EXPECT_GE(length, static_cast<int>(static_cast<float>(source) / options.max_speed) - 1);
    EXPECT_LE(length, static_cast<int>(static_cast<float>(source) / options.min_speed) + 1);
    shorter += length < source;
    longer += length > source;
  }
  EXPECT_GT(shorter, 0);
  EXPECT_GT(longer, 0);
  // Same seed, same library; another seed, another one.
  EXPECT_TRUE(synthesize_library(real, options).value().features().isApprox(big.features()));
  options.seed = 2;
  EXPECT_FALSE(synthesize_library(real, options).value().features().isApprox(big.features()));
}

TEST(SyntheticLibrary, KeepsTheRealTakesFirstAndNamesEachCopysSource) {
  const TemplateModel real = test::make_model({200, 150}, 12, 5, 60.0, 4);
  SyntheticLibraryOptions options;
  options.num_states = 3000;
  options.keep_real_takes = true;
  const TemplateModel big = synthesize_library(real, options).value();
  ASSERT_EQ(big.num_states(), 3000);
  EXPECT_TRUE(big.features().topRows(350).isApprox(real.features()));
  EXPECT_EQ(big.take_begin(1), 200);
  EXPECT_EQ(big.take_begin(2), 350);

  const std::vector<SyntheticTakeSource> sources = synthetic_take_sources(real, options).value();
  ASSERT_EQ(static_cast<int>(sources.size()), big.num_takes());
  for (int k = 0; k < big.num_takes(); ++k) {
    const SyntheticTakeSource& source = sources[static_cast<std::size_t>(k)];
    const int real_begin = real.take_begin(source.real_take);
    EXPECT_EQ(source.real_length, real.take_end(source.real_take) - real_begin);
    if (k < 2) {
      EXPECT_EQ(source.real_take, k);
      EXPECT_EQ(source.speed, 1.0f);
      continue;
    }
    EXPECT_GE(source.speed, options.min_speed);
    EXPECT_LE(source.speed, options.max_speed);
    // The copy's frame t shows the real frame real_frame(t): its posture features are the real
    // ones up to the noise and the interpolation between neighbouring frames.
    const int posture = big.num_dims() - big.velocity_dims();
    for (int t = 0; t < big.take_end(k) - big.take_begin(k); t += 17) {
      const int shown = source.real_frame(t);
      ASSERT_GE(shown, 0);
      ASSERT_LT(shown, source.real_length);
      const float gap = (big.features().row(big.take_begin(k) + t).head(posture) -
                         real.features().row(real_begin + shown).head(posture))
                            .cwiseAbs()
                            .maxCoeff();
      EXPECT_LT(gap, 0.2f) << "take " << k << " frame " << t;
    }
  }
  // A library smaller than the real one cannot keep it.
  options.num_states = 300;
  EXPECT_FALSE(synthesize_library(real, options));
  EXPECT_FALSE(synthetic_take_sources(real, options));
}

TEST(SyntheticLibrary, MirrorsEverySecondCopy) {
  const TemplateModel real = test::make_model({200, 150}, 6, 5, 60.0, 2);
  SyntheticLibraryOptions options;
  options.num_states = 1400;
  options.min_speed = options.max_speed = 1.0f;
  options.noise = 0.0f;
  // A mirror map of the kind feature_mirror() makes: dims 0 and 1 swap, 2 flips about 0.5.
  options.mirror = {{1, 1.0f, 0.0f}, {0, 1.0f, 0.0f}, {2, -1.0f, 1.0f},
                    {3, 1.0f, 0.0f}, {4, 1.0f, 0.0f}, {5, -1.0f, 0.0f}};
  const TemplateModel big = synthesize_library(real, options).value();
  const std::vector<SyntheticTakeSource> sources = synthetic_take_sources(real, options).value();
  ASSERT_EQ(static_cast<int>(sources.size()), big.num_takes());
  for (int k = 0; k < big.num_takes(); ++k) {
    const SyntheticTakeSource& source = sources[static_cast<std::size_t>(k)];
    EXPECT_EQ(source.mirrored, k % 2 == 1);
    const int real_begin = real.take_begin(source.real_take);
    const int row = big.take_begin(k) + 10;
    const auto x = real.features().row(real_begin + 10);
    if (source.mirrored) {
      EXPECT_FLOAT_EQ(big.features()(row, 0), x(1));
      EXPECT_FLOAT_EQ(big.features()(row, 1), x(0));
      EXPECT_FLOAT_EQ(big.features()(row, 2), TemplateModel::held_precision(1.0f - x(2)));
      EXPECT_FLOAT_EQ(big.features()(row, 5), -x(5));
    } else {
      EXPECT_TRUE(big.features().row(row).isApprox(x));
    }
  }
  options.mirror.pop_back();
  EXPECT_FALSE(synthesize_library(real, options));
}

TEST(SyntheticLibrary, RejectsBadOptions) {
  const TemplateModel real = test::make_model({50}, 4, 1);
  SyntheticLibraryOptions options;
  options.num_states = 2;
  EXPECT_FALSE(synthesize_library(real, options));
  options.num_states = 100;
  options.min_speed = 0.0f;
  Result<TemplateModel> bad = synthesize_library(real, options);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("speed"), std::string::npos);
}

}  // namespace
}  // namespace duet
