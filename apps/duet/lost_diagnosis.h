// `duet follow` must not fail silently (issue 10): when most of the input was lost, say so and
// name the causes that can be checked — the frame rate, the units, the rig's roles, the role the
// user danced — instead of writing a partner that follows nothing.
#pragma once

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "duet/follow/tracker.h"
#include "duet/io/motion_file.h"
#include "duet/live/duet_library.h"

namespace duet::app {

// Over this share of lost frames `duet follow` exits kExitLost (unless --allow-lost).
constexpr double kMostlyLostFraction = 0.5;

struct LostSummary {
  int frames = 0;
  int lost = 0;
  int jumps = 0;
  int missing = 0;   // no usable pose, or the sensor repeated the last one (FollowResult::missing)
  int outliers = 0;  // evidence set aside (FollowResult::outlier)
  int partly_observed = 0;  // a controller repeating its last pose (FollowResult::partly_observed)
  int held_still = 0;  // lost only for holding one place for seconds (FollowResult::held_still)
  int lost_unseen = 0;  // lost while missing: seconds without a new pose (missing_lost_s)
  double lost_fraction() const { return frames > 0 ? static_cast<double>(lost) / frames : 0.0; }
};
LostSummary summarise_lost(std::span<const FollowResult> results);
// " (frames without evidence: M missing or repeated, K outliers set aside; P with a hand unseen)",
// or "" when none.
std::string describe_set_aside(const LostSummary& summary);

// What the input looked like, for the checks.
struct LostContext {
  const LoadedMotion* input = nullptr;
  double input_rate_hz = 0.0;    // the rate the input was followed at
  double library_rate_hz = 0.0;
  DancerRole role = DancerRole::kLeader;
  float median_tempo = 1.0f;  // median_followed_tempo of the results
  // Lost fraction when the same input is followed as the other dancer (if it was tried).
  std::optional<double> other_role_lost_fraction;
};

// The follower's median tempo over the frames it did not flag lost (over every frame when fewer
// than a tenth were followed), leaving out frames lost for standing still; 1 without frames.
float median_followed_tempo(std::span<const FollowResult> results);

// A dancer's own tempo stays within these of the library's (method.md 7 performs 0.7x-1.4x);
// a median outside them says the input's clock runs at another speed: a wrong frame rate.
constexpr float kSlowestDancerTempo = 0.66f;
constexpr float kFastestDancerTempo = 1.5f;

// One line of advice when the median tempo says the input's frame rate is wrong, naming the rate
// to pass (snapped to a common capture rate when one is near); nothing otherwise. Checked also
// when the input was followed: a 60 Hz take read at its header's 120 fps is followed at twice the
// tempo, in fast motion, and none of it is lost.
std::optional<std::string> rate_mismatch(double input_rate_hz, double library_rate_hz,
                                         float median_tempo);

// The likely causes, most likely first; one line each, phrased as advice. Never empty.
std::vector<std::string> diagnose_lost(const LostSummary& summary, const LostContext& context);

}  // namespace duet::app
