// The library model cache file: what is written is read back (model and index), and a missing,
// truncated, foreign, stale or damaged cache is rejected with a message naming the file and the
// problem, then rebuilt by load_or_build_model_cache.
#include "duet/follow/model_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "duet/follow/beam_follower.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

constexpr std::uint64_t kSpec = 0x5eed;

class ModelCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("duet_model_cache_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "salsa.model").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  void write() {
    ASSERT_TRUE(
        write_model_cache(path_, model_, JumpCandidateIndex::build(model_).value(), kSpec).ok());
  }
  std::string rejected(std::uint64_t spec = kSpec) {
    Result<CachedModel> read = read_model_cache(path_, spec);
    EXPECT_FALSE(read);
    return read ? std::string() : read.error().message;
  }
  void patch(std::size_t offset, const std::vector<unsigned char>& bytes) {
    std::fstream file(path_, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(static_cast<std::streamoff>(offset));
    file.write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  }

  TemplateModel model_ = test::make_model({300, 200}, 20, 3, 60.0, 4);
  std::filesystem::path dir_;
  std::string path_;
};

TEST_F(ModelCacheTest, ReadsBackTheModelAndAnIndexThatFindsTheSameCandidates) {
  write();
  Result<CachedModel> read = read_model_cache(path_, kSpec);
  ASSERT_TRUE(read) << read.error().message;
  const TemplateModel& model = read.value().model;
  EXPECT_EQ(model.features(), model_.features());
  EXPECT_EQ(model.num_takes(), 2);
  EXPECT_EQ(model.take_begin(1), 300);
  EXPECT_EQ(model.velocity_dims(), 4);
  EXPECT_EQ(model.frame_rate_hz(), 60.0);
  const JumpCandidateIndex built = JumpCandidateIndex::build(model_).value();
  for (const double position : {10.0, 123.4, 450.0}) {
    const std::vector<float> phi = test::features_at(model_, position);
    std::uint32_t a[16], b[16];
    float da[16], db[16], bound_a = 0, bound_b = 0;
    ASSERT_EQ(built.nearest(phi.data(), 16, a, da, bound_a), 16);
    ASSERT_EQ(read.value().index.nearest(phi.data(), 16, b, db, bound_b), 16);
    for (int k = 0; k < 16; ++k) EXPECT_EQ(a[k], b[k]);
    EXPECT_EQ(bound_a, bound_b);
  }
  // A beam follower runs on what was read.
  Result<BeamFollower> beam = BeamFollower::create(
      model, {}, {}, std::make_shared<const JumpCandidateIndex>(std::move(read).value().index));
  ASSERT_TRUE(beam) << beam.error().message;
  EXPECT_GE(beam.value().step(test::features_at(model, 40.0), 1.0 / 60).state, 0);
}

TEST_F(ModelCacheTest, AModelReadFromTheCacheKeepsItsMappedFeaturesAlive) {
  // The row-major features stay in the file's map (so a 1M-state library keeps 200 MB on disk);
  // the map lives as long as any copy of the model, also after the file is gone.
  write();
  Result<CachedModel> read = read_model_cache(path_, kSpec);
  ASSERT_TRUE(read) << read.error().message;
  const TemplateModel copy = read.value().model;
  read = Error{"dropped"};  // the cached model and its index are gone; the copy remains
  std::filesystem::remove(path_);
  EXPECT_EQ(copy.features(), model_.features());
  EXPECT_TRUE(std::equal(copy.blocked_features().begin(), copy.blocked_features().end(),
                         model_.blocked_features().begin(), model_.blocked_features().end()));
}

TEST_F(ModelCacheTest, RejectsMissingTruncatedForeignStaleAndDamagedCaches) {
  EXPECT_NE(rejected().find("cannot open"), std::string::npos);
  write();
  EXPECT_NE(rejected(kSpec + 1).find("another library or feature spec"), std::string::npos);
  const auto full = std::filesystem::file_size(path_);
  std::filesystem::resize_file(path_, full - 100);
  const std::string truncated = rejected();
  EXPECT_NE(truncated.find(path_), std::string::npos) << truncated;
  EXPECT_NE(truncated.find("truncated"), std::string::npos) << truncated;
  std::filesystem::resize_file(path_, 20);
  EXPECT_NE(rejected().find("shorter than its header"), std::string::npos);

  write();
  patch(0, {'N', 'O', 'T', 'A', 'C', 'A', 'C', 'H'});
  EXPECT_NE(rejected().find("not a Duet model cache"), std::string::npos);
  write();
  patch(8, {99, 0, 0, 0});  // the version
  EXPECT_NE(rejected().find("version 99"), std::string::npos);
  write();
  patch(full - 5000, {0xde, 0xad, 0xbe, 0xef});  // inside the features
  EXPECT_NE(rejected().find("checksum"), std::string::npos);
}

TEST_F(ModelCacheTest, LoadOrBuildRebuildsABadCacheAndThenUsesIt) {
  { std::ofstream(path_) << "something else entirely"; }
  int builds = 0;
  auto build = [&]() -> Result<TemplateModel> {
    ++builds;
    return model_;
  };
  std::string why;
  Result<CachedModel> first = load_or_build_model_cache(path_, kSpec, build, &why);
  ASSERT_TRUE(first) << first.error().message;
  EXPECT_EQ(builds, 1);
  EXPECT_NE(why.find("not a Duet model cache"), std::string::npos) << why;
  Result<CachedModel> second = load_or_build_model_cache(path_, kSpec, build, &why);
  ASSERT_TRUE(second) << second.error().message;
  EXPECT_EQ(builds, 1);
  EXPECT_TRUE(why.empty()) << why;
  EXPECT_EQ(second.value().model.features(), model_.features());
}

}  // namespace
}  // namespace duet
