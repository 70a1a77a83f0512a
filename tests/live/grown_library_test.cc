// A grown library (issue 13 scale tests in the live path): the salsa takes plus time-warped,
// noisy copies, built once and then read from the model cache; a real take followed through it
// with the beam is reported at the captured take's frames, without jumps between copies.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <span>
#include <string_view>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "duet/follow/beam_follower.h"
#include "duet/follow/tracker.h"
#include "duet/live/duet_library.h"
#include "duet/live/follow_session.h"
#include "salsa_library.h"

namespace duet {
namespace {

using test::kSalsaData;

std::vector<PairFiles> two_salsa_pairs() {
  std::vector<PairFiles> pairs;
  for (const char* trial : {"05", "07"}) {
    pairs.push_back({{kSalsaData + "/cmu-salsa/bvh/60/60_" + trial + "_scaled.bvh"},
                     {kSalsaData + "/cmu-salsa/bvh/61/61_" + trial + "_scaled.bvh"}});
  }
  return pairs;
}

Result<DuetLibrary> grown_library(int states, const std::string& cache) {
  LibraryOptions options;
  options.load.frame_rate = 60.0;
  options.grow_to_states = states;
  options.model_cache = cache;
  return DuetLibrary::load(two_salsa_pairs(), options);
}

class GrownLibrary : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("duet-grown-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(GrownLibrary, IsBuiltOnceThenReadFromTheCache) {
  const std::string cache = (dir_ / "model.cache").string();
  Result<DuetLibrary> first = grown_library(20000, cache);
  ASSERT_TRUE(first) << first.error().message;
  EXPECT_TRUE(first.value().grown());
  EXPECT_EQ(first.value().model().num_states(), 20000);
  EXPECT_GT(first.value().model().num_takes(), 2);
  EXPECT_NE(first.value().model_cache_note().find("cannot open"), std::string::npos)
      << first.value().model_cache_note();
  ASSERT_NE(first.value().candidate_index(), nullptr);

  Result<DuetLibrary> second = grown_library(20000, cache);
  ASSERT_TRUE(second) << second.error().message;
  EXPECT_EQ(second.value().model_cache_note(), "");
  EXPECT_TRUE(second.value().model().features().isApprox(first.value().model().features()));
  EXPECT_EQ(second.value().model().num_takes(), first.value().model().num_takes());

  // Another size is another library: the cache is rebuilt, saying why.
  Result<DuetLibrary> other = grown_library(21000, cache);
  ASSERT_TRUE(other) << other.error().message;
  EXPECT_NE(other.value().model_cache_note().find("another library"), std::string::npos)
      << other.value().model_cache_note();
  EXPECT_EQ(other.value().model().num_states(), 21000);

  // Below the captured takes' size it cannot grow.
  Result<DuetLibrary> small = grown_library(100, "");
  ASSERT_FALSE(small);
  EXPECT_NE(small.error().message.find("cannot grow to 100 states"), std::string::npos)
      << small.error().message;
}

TEST_F(GrownLibrary, ReportsTheCapturedPlaceWhicheverCopyIsFollowed) {
  Result<DuetLibrary> library = grown_library(20000, (dir_ / "model.cache").string());
  ASSERT_TRUE(library) << library.error().message;
  const DuetLibrary& lib = library.value();
  // Every copy maps into its captured take.
  for (int take = 0; take < lib.model().num_takes(); ++take) {
    const int frames = lib.model().take_end(take) - lib.model().take_begin(take);
    for (const int frame : {0, frames / 2, frames - 1}) {
      const LibraryPlace place = lib.place_of(take, frame);
      ASSERT_GE(place.take, 0);
      ASSERT_LT(place.take, 2);
      ASSERT_GE(place.frame, 0);
      ASSERT_LT(place.frame, lib.takes()[static_cast<std::size_t>(place.take)]
                                 .template_motion.clip.frame_count());
    }
  }
  EXPECT_EQ(lib.place_of(lib.model().num_takes(), 0).take, -1);

  // Take 07's leader, followed with the beam through 20,000 states of which 18,000 are copies.
  const LoadedMotion& input = lib.takes()[1].template_motion;
  Result<BeamFollower> beam = BeamFollower::create(lib.model(), {}, {}, lib.candidate_index());
  ASSERT_TRUE(beam) << beam.error().message;
  Result<FollowSession> session =
      FollowSession::create(lib, input.clip.skeleton_ptr(), input.roles,
                            std::make_unique<BeamFollower>(std::move(beam).value()));
  ASSERT_TRUE(session) << session.error().message;
  const Clip& clip = input.clip;
  int within = 0, jumps = 0, in_copies = 0;
  for (int f = 0; f < clip.frame_count(); ++f) {
    const FollowResult r =
        session.value().step(clip.translations_ls(f), clip.rotations_ls(f), f / clip.frame_rate());
    within += r.take == 1 && std::abs(r.frame_in_take - f) <= 6 ? 1 : 0;  // within 100 ms
    jumps += r.jumped ? 1 : 0;
    in_copies += lib.model().take_of(r.state) >= 2 ? 1 : 0;
  }
  const double share = static_cast<double>(within) / clip.frame_count();
  std::printf("grown library: %.2f%% within 100 ms, %d jumps, %d of %d frames in copies\n",
              100.0 * share, jumps, in_copies, clip.frame_count());
  EXPECT_GE(share, 0.97);
  EXPECT_LE(jumps, 3);
}

// Plays back a list of results, whatever the input.
class ScriptedTracker final : public Tracker {
 public:
  explicit ScriptedTracker(std::vector<FollowResult> script) : script_(std::move(script)) {}
  void reset() noexcept override { next_ = 0; }
  FollowResult step(std::span<const float>, double) noexcept override {
    return script_[std::min(next_++, script_.size() - 1)];
  }
  std::string_view name() const noexcept override { return "scripted"; }

 private:
  std::vector<FollowResult> script_;
  std::size_t next_ = 0;
};

TEST_F(GrownLibrary, AMoveBetweenCopiesOfOneMomentIsNoJump) {
  Result<DuetLibrary> library = grown_library(20000, "");
  ASSERT_TRUE(library) << library.error().message;
  const DuetLibrary& lib = library.value();
  const TemplateModel& model = lib.model();
  // Two copies of captured take 1, and the frame of each that shows its frame 300.
  std::vector<int> copies;
  for (int take = 2; take < model.num_takes() && copies.size() < 2; ++take) {
    if (lib.place_of(take, 0).take == 1 && model.take_end(take) - model.take_begin(take) > 900) {
      copies.push_back(take);
    }
  }
  ASSERT_EQ(copies.size(), 2u);
  auto frame_showing = [&](int copy, int captured_frame) {
    int best = 0;
    for (int t = 0; t < model.take_end(copy) - model.take_begin(copy); ++t) {
      if (std::abs(lib.place_of(copy, t).frame - captured_frame) <
          std::abs(lib.place_of(copy, best).frame - captured_frame)) {
        best = t;
      }
    }
    return best;
  };
  auto at = [&](int copy, int frame, bool jumped) {
    FollowResult r;
    r.take = copy;
    r.frame_in_take = frame;
    r.state = model.take_begin(copy) + frame;
    r.jumped = jumped;
    r.best_distance_per_dim = 1e9f;  // nothing for the posture bias to learn
    return r;
  };
  const int a = frame_showing(copies[0], 300);
  const int b = frame_showing(copies[1], 301);
  const int c = frame_showing(copies[1], 700);
  std::vector<FollowResult> script = {at(copies[0], a, false), at(copies[1], b, true),
                                      at(copies[1], c, true)};
  const LoadedMotion& input = lib.takes()[1].template_motion;
  Result<FollowSession> session =
      FollowSession::create(lib, input.clip.skeleton_ptr(), input.roles,
                            std::make_unique<ScriptedTracker>(std::move(script)));
  ASSERT_TRUE(session) << session.error().message;
  std::vector<FollowResult> out;
  for (int f = 0; f < 3; ++f) {
    out.push_back(session.value().step(input.clip.translations_ls(f), input.clip.rotations_ls(f),
                                       f / 60.0));
  }
  EXPECT_EQ(out[0].take, 1);
  EXPECT_NEAR(out[0].frame_in_take, 300, 1);
  EXPECT_EQ(out[0].state, model.take_begin(copies[0]) + a);  // the model's state is kept
  EXPECT_EQ(out[1].take, 1);
  EXPECT_NEAR(out[1].frame_in_take, 301, 1);
  EXPECT_FALSE(out[1].jumped);  // another copy of the same moment
  EXPECT_EQ(out[2].take, 1);
  EXPECT_NEAR(out[2].frame_in_take, 700, 1);
  EXPECT_TRUE(out[2].jumped);  // another moment
}

}  // namespace
}  // namespace duet
