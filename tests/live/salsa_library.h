// Test support: the 14-duet salsa library (27,495 template states at 60 Hz, user role leader)
// loaded once per test binary from DUET_DATA_DIR, and a whole clip followed through it.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "duet/follow/hmm_follower.h"
#include "duet/io/motion_file.h"
#include "duet/live/duet_library.h"
#include "duet/live/follow_session.h"

namespace duet::test {

inline const std::string kSalsaData = DUET_DATA_DIR;

// The 14 duets with features of `points` (the whole body, or a headset's head and hands).
inline DuetLibrary load_salsa_library(InputPoints points) {
  std::vector<PairFiles> pairs;
  for (const char* trial :
       {"01", "02", "03", "04", "05", "06", "07", "09", "10", "11", "12", "13", "14", "15"}) {
    pairs.push_back({{kSalsaData + "/cmu-salsa/bvh/60/60_" + trial + "_scaled.bvh"},
                     {kSalsaData + "/cmu-salsa/bvh/61/61_" + trial + "_scaled.bvh"}});
  }
  LibraryOptions options;
  options.load.frame_rate = 60.0;
  options.features.input_points = points;
  Result<DuetLibrary> l = DuetLibrary::load(pairs, options);
  if (!l) throw std::runtime_error(l.error().message);
  return std::move(l).value();
}

inline const DuetLibrary& salsa_library() {
  static const DuetLibrary loaded = load_salsa_library(InputPoints::kFullBody);
  return loaded;
}

// The same duets with three points' features (a headset's head and hands), loaded once per test
// binary.
inline const DuetLibrary& head_hands_library() {
  static const DuetLibrary loaded = load_salsa_library(InputPoints::kHeadHands);
  return loaded;
}

// A follow session of `library` for a user on `skeleton` with `roles`, followed by the HMM with
// `params`; throws (failing the test) when either cannot be made.
inline FollowSession hmm_session(const DuetLibrary& library,
                                 std::shared_ptr<const Skeleton> skeleton, const JointRoles& roles,
                                 const FollowParams& params = {}) {
  Result<HmmFollower> follower = HmmFollower::create(library.model(), params);
  if (!follower) throw std::runtime_error(follower.error().message);
  Result<FollowSession> session =
      FollowSession::create(library, std::move(skeleton), roles,
                            std::make_unique<HmmFollower>(std::move(follower).value()));
  if (!session) throw std::runtime_error(session.error().message);
  return std::move(session).value();
}

// Every frame of `input` through a FollowSession with `tracker`, one result per frame.
inline std::vector<FollowResult> follow_clip(const LoadedMotion& input,
                                             std::unique_ptr<Tracker> tracker) {
  Result<FollowSession> session = FollowSession::create(salsa_library(), input.clip.skeleton_ptr(),
                                                        input.roles, std::move(tracker));
  EXPECT_TRUE(session) << session.error().message;
  std::vector<FollowResult> results;
  for (int f = 0; f < input.clip.frame_count(); ++f) {
    results.push_back(session.value().step(
        input.clip.translations_ls(f), input.clip.rotations_ls(f), f / input.clip.frame_rate()));
  }
  return results;
}

// The same with the default HMM.
inline std::vector<FollowResult> follow_clip(const LoadedMotion& input) {
  Result<HmmFollower> follower = HmmFollower::create(salsa_library().model(), FollowParams{});
  EXPECT_TRUE(follower) << follower.error().message;
  return follow_clip(input, std::make_unique<HmmFollower>(std::move(follower).value()));
}

}  // namespace duet::test
