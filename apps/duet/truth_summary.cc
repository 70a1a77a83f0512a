#include "truth_summary.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "duet/eval/metrics.h"

namespace duet::app {

namespace {

constexpr const char* kHeader = "frame,time_s,take,template_frame,in_pause,jump";

bool parse_row(const std::string& line, double (&fields)[6]) {
  std::istringstream in(line);
  std::string cell;
  for (double& field : fields) {
    if (!std::getline(in, cell, ',')) return false;
    try {
      std::size_t used = 0;
      field = std::stod(cell, &used);
      if (used != cell.size() || !std::isfinite(field)) return false;
    } catch (const std::exception&) {
      return false;
    }
  }
  return !std::getline(in, cell, ',');
}

}  // namespace

Result<GroundTruth> read_ground_truth(const std::string& path) {
  std::ifstream in(path);
  if (!in) return make_error(path, 0, "cannot open ground truth");
  std::string line;
  if (!std::getline(in, line) || line != kHeader) {
    return make_error(path, 1, std::string("expected the header '") + kHeader + "'");
  }
  GroundTruth truth;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    double f[6];
    if (!parse_row(line, f)) {
      return make_error(path, line_number, "expected six numbers: " + std::string(kHeader));
    }
    if (f[0] != static_cast<double>(truth.rows.size())) {
      return make_error(path, line_number, "frames must count up from 0");
    }
    truth.lines.push_back(line_number);
    truth.times_s.push_back(f[1]);
    truth.rows.push_back(TruthFrame{static_cast<int>(f[2]), f[3], f[4] != 0.0, f[5] != 0.0});
  }
  return truth;
}

Status check_ground_truth(const GroundTruth& truth, const std::string& path,
                          std::span<const int> take_frames) {
  const auto takes = static_cast<int>(take_frames.size());
  for (std::size_t i = 0; i < truth.rows.size(); ++i) {
    const TruthFrame& row = truth.rows[i];
    if (row.take < 0 || row.take >= takes) {
      return make_error(path, truth.lines[i],
                        fmt::format("take {} is not in the library, which has {} take(s) "
                                    "(0..{}): is this the truth of a performance made from "
                                    "another library or --pair list?",
                                    row.take, takes, takes - 1));
    }
    // One frame of slack: improvise writes positions up to the last frame.
    const int frames = take_frames[static_cast<std::size_t>(row.take)];
    if (!(row.template_frame >= -1.0 && row.template_frame <= frames)) {
      return make_error(path, truth.lines[i],
                        fmt::format("template frame {} is outside take {} (frames 0..{}): is "
                                    "the library read at another frame rate (--fps)?",
                                    row.template_frame, row.take, frames - 1));
    }
  }
  return Ok{};
}

void print_accuracy_summary(const GroundTruth& truth, std::span<const FollowResult> results,
                            double template_rate_hz) {
  std::vector<FrameEstimate> estimates;
  estimates.reserve(results.size());
  for (const FollowResult& r : results) {
    estimates.push_back(frame_estimate(r));
  }
  MetricsAccumulator accumulator;
  accumulator.add(truth.rows, truth.times_s, estimates, template_rate_hz);
  const Metrics m = accumulator.summary();
  fmt::print("accuracy against the ground truth ({} frames scored, {} pause frames left out):\n",
             m.scored_frames, m.pause_frames);
  fmt::print("  within 50 / 100 / 300 ms: {:.1f}% / {:.1f}% / {:.1f}%\n", 100 * m.within_50ms,
             100 * m.within_100ms, 100 * m.within_300ms);
  fmt::print("  mean error {:.0f} ms, median {:.0f} ms; wrong take {:.1f}%\n", m.mean_error_ms,
             m.median_error_ms, 100 * m.miss_fraction);
  fmt::print("  jumps recovered {}/{}, median recovery {:.2f} s\n", m.recovered_jumps, m.jumps,
             m.median_recovery_s);
}

}  // namespace duet::app
