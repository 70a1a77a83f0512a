// Runs the partner synthesis over a synthetic performance exactly as `duet follow` does (the
// LiveLoop of method.md 6: features -> tracker -> PartnerSynthesisJob), once per configuration of
// the corrections (method.md 5), and scores every frame with partner_metrics.h.
//
// The tracker runs for real once (a recording pass, timed as the whole loop); every configuration
// then runs the same LiveLoop with a tracker that replays those estimates, so each configuration
// sees exactly the estimates the tracker gave (the trackers are deterministic) and the follower's
// cost is paid once. Offline code.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/eval/partner_metrics.h"
#include "duet/eval/performance.h"
#include "duet/follow/tracker.h"
#include "duet/live/duet_library.h"
#include "duet/partner/partner_synthesis.h"

namespace duet {

struct PartnerConfig {
  std::string name;
  PartnerParams params;
};

// In report order: "all" (every correction, the defaults), "no-contact", "no-footlock",
// "no-blend", "no-smooth" (each one switched off), "align-only" (the response pose at the
// estimate, only placed) and "none" (every correction off: the floor of the loop's cost; the
// partner is then in the capture's frame, so joint and hand errors are not comparable).
std::vector<PartnerConfig> standard_partner_configs(const PartnerParams& base = {});

struct PartnerPerformanceResult {
  std::vector<PartnerMetricsAccumulator> configs;  // one per config, in the given order
  double loop_step_us = 0.0;  // mean LiveLoop::step with the real tracker (recording pass)
};

// library must outlive the call; performance comes from it (truth takes index its takes).
// tracker: a fresh tracker on library.model() (it is moved into the loop).
Result<PartnerPerformanceResult> run_partner_performance(const DuetLibrary& library,
                                                         const Performance& performance,
                                                         std::unique_ptr<Tracker> tracker,
                                                         std::span<const PartnerConfig> configs,
                                                         const PartnerMetricsOptions& options);

}  // namespace duet
