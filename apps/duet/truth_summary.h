// `duet follow --truth`: reads the ground truth that `duet improvise` wrote and prints how well
// the follower did (the metrics of the eval module, docs/evaluation.md).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/eval/performance.h"
#include "duet/follow/tracker.h"

namespace duet::app {

struct GroundTruth {
  std::vector<TruthFrame> rows;
  std::vector<double> times_s;
};

// CSV with the header frame,time_s,take,template_frame,in_pause,jump. Errors: "file:line: reason".
Result<GroundTruth> read_ground_truth(const std::string& path);

void print_accuracy_summary(const GroundTruth& truth, std::span<const FollowResult> results,
                            double template_rate_hz);

}  // namespace duet::app
