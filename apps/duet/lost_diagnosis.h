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
  double lost_fraction() const { return frames > 0 ? static_cast<double>(lost) / frames : 0.0; }
};
LostSummary summarise_lost(std::span<const FollowResult> results);
// " (frames without evidence: M missing or repeated, K outliers set aside)", or "" when none.
std::string describe_set_aside(const LostSummary& summary);

// What the input looked like, for the checks.
struct LostContext {
  const LoadedMotion* input = nullptr;
  double input_rate_hz = 0.0;    // the rate the input was followed at
  double library_rate_hz = 0.0;
  DancerRole role = DancerRole::kLeader;
  float median_tempo = 1.0f;     // the follower's tempo estimate over the tracked frames
  // Lost fraction when the same input is followed as the other dancer (if it was tried).
  std::optional<double> other_role_lost_fraction;
};

// The likely causes, most likely first; one line each, phrased as advice. Never empty.
std::vector<std::string> diagnose_lost(const LostSummary& summary, const LostContext& context);

}  // namespace duet::app
