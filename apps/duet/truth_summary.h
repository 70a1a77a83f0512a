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
  std::vector<int> lines;  // the file line of each row, for errors
};

// CSV with the header frame,time_s,take,template_frame,in_pause,jump. Errors: "file:line: reason".
Result<GroundTruth> read_ground_truth(const std::string& path);

// Checks that the truth belongs to this library: every row's take is one of its takes and its
// template frame lies within that take. A truth file for another library (or another --take
// numbering) would otherwise score every frame as a miss and still exit 0.
// `take_frames[k]` is the frame count of take k's template.
Status check_ground_truth(const GroundTruth& truth, const std::string& path,
                          std::span<const int> take_frames);

void print_accuracy_summary(const GroundTruth& truth, std::span<const FollowResult> results,
                            double template_rate_hz);

}  // namespace duet::app
