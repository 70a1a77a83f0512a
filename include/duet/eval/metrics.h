// Following metrics against ground truth (method.md 7). Exact definitions in docs/evaluation.md.
//
// Per frame, the error is |estimated - true template time| in milliseconds of template time. An
// estimate in the wrong take, or no estimate, is a miss: its error is miss_error_ms. Errors above
// miss_error_ms are capped there too, so one lost stretch cannot dominate the mean and the mean
// stays comparable between trackers. Pause frames (the user holds still before a jump) have no
// single right answer and are left out of every accuracy and error number.
#pragma once

#include <span>
#include <vector>

#include "duet/eval/calibration.h"
#include "duet/eval/performance.h"
#include "duet/follow/tracker.h"

namespace duet {

class LookAlikeFrames;

// What a tracker said about one input frame (a FollowResult reduced to what is scored).
struct FrameEstimate {
  int take = -1;           // -1: no estimate
  int frame_in_take = -1;  // template frame within take
  bool lost = false;
  bool jumped = false;
  double step_us = 0.0;  // wall-clock time of the session step for this frame, microseconds
  float confidence = 0.0f;  // FollowResult::confidence: P(within 100 ms) as the tracker claims it
  // What the confidence and lost decisions were made from (FollowResult), for fitting them.
  float window_mass = 0.0f;
  float best_distance_per_dim = 0.0f;
  float sensor_noise_per_dim = 0.0f;
  float rig_offset = 0.0f;
  float rig_offset_learnt_s = 0.0f;
  float tracker_confidence = 0.0f;
  bool in_pause = false;
  bool outlier = false;  // FollowResult::outlier: the frame's evidence was set aside
  float frame_offset = 0.0f;  // FollowResult::frame_offset: where between frames
};

// A follower's result as scored; step_us its measured wall-clock time.
FrameEstimate frame_estimate(const FollowResult& result, double step_us = 0.0);

struct MetricsOptions {
  double miss_error_ms = 1000.0;         // error of a miss, and cap of every error
  double recovery_tolerance_ms = 100.0;  // recovered: within this of the truth ...
  double recovery_hold_s = 0.1;          // ... for this long (at least 3 frames)
  // A reported jump answers a true one when it falls from just before that jump's pause (or the
  // jump itself) to this long after the jump; any other reported jump is false.
  double jump_answer_window_s = 1.0;
  double jump_answer_lead_s = 0.1;
  // A performance is found (Metrics::median_find_s) at the first frame from which the estimate
  // stays within recovery_tolerance_ms for this long.
  double find_hold_s = 1.0;
};

// Error of one frame in ms of template time, capped at options.miss_error_ms (a wrong take or no
// estimate is a miss).
double frame_error_ms(const TruthFrame& truth, const FrameEstimate& estimate,
                      double template_rate_hz, const MetricsOptions& options);

struct Metrics {
  long long frames = 0;         // all input frames
  long long scored_frames = 0;  // frames not in a pause
  long long pause_frames = 0;
  // Fractions of the scored frames whose error is within 50 / 100 / 300 ms.
  double within_50ms = 0.0;
  double within_100ms = 0.0;
  double within_300ms = 0.0;
  // Within 100 ms, or showing what the true frame shows (look_alike_frames.h: the dancers
  // standing at another take's start look alike, and so do their partners); equal to
  // within_100ms when no judge was given.
  double within_100ms_alike = 0.0;
  double miss_fraction = 0.0;  // scored frames in the wrong take or without estimate
  double mean_error_ms = 0.0;  // over scored frames, each capped at miss_error_ms
  double median_error_ms = 0.0;
  // Jumps: true jumps (TruthFrame::jump), except one less than 1 s before the end of its
  // performance. A jump is recovered at the first frame from which the error stays within
  // recovery_tolerance_ms for recovery_hold_s (and at least 3 frames), with that whole hold before
  // the next pause or jump; the recovery time is that frame's timestamp minus the jump frame's.
  // Unrecovered jumps count as infinitely slow in the median.
  long long jumps = 0;
  long long recovered_jumps = 0;
  double median_recovery_s = 0.0;  // +inf when half or more are unrecovered; 0 without jumps
  double mean_recovery_s = 0.0;    // over the recovered jumps only
  double lost_fraction = 0.0;      // scored frames the tracker flagged as lost
  // Lost among the frames the tracker actually follows (scored, within 100 ms): a lost flag there
  // is a false alarm (issue 11).
  double lost_on_tracked_fraction = 0.0;
  // How often the lost flag changes (either way) per minute of performance: what a client that
  // shows or acts on it (OSC /duet/lost, the partner's coasting) sees flicker.
  double lost_switches_per_minute = 0.0;
  // Jumps the tracker reported (FrameEstimate::jumped) and those that answer no true jump (see
  // MetricsOptions::jump_answer_window_s), per minute of performance.
  long long reported_jumps = 0;
  long long false_jumps = 0;
  double false_jumps_per_minute = 0.0;
  // Finding the dance: the time from a performance's first frame to the first frame from which
  // the estimate stays within recovery_tolerance_ms for find_hold_s (pause frames neither break
  // nor count), the median and the largest over the performances (+inf for one never found, in
  // the median when half or more are), and within 100 ms over the scored frames from there on.
  // Every take starts with both dancers standing, and standing starts look alike across takes:
  // this tells a start the follower has to guess apart from a dance it loses (issues 10, 11).
  double median_find_s = 0.0;
  double worst_find_s = 0.0;
  double within_100ms_found = 0.0;
  double mean_step_us = 0.0;  // mean wall-clock time per session step (measured)
  // Calibration of the confidence against "within 100 ms" over the scored frames (calibration.h).
  double confidence_ece = 0.0;
  ReliabilityDiagram reliability{};
};

// Collects per-frame errors of several performances and summarises them (pooled over frames and
// jumps, so longer performances weigh more).
class MetricsAccumulator {
 public:
  explicit MetricsAccumulator(MetricsOptions options = {}) : options_(options) {}

  // truth, times_s and estimates have one entry per frame. look_alikes (optional) judges which
  // estimates more than 100 ms off show what the truth shows (Metrics::within_100ms_alike).
  void add(std::span<const TruthFrame> truth, std::span<const double> times_s,
           std::span<const FrameEstimate> estimates, double template_rate_hz,
           const LookAlikeFrames* look_alikes = nullptr);
  void add(const Performance& performance, std::span<const FrameEstimate> estimates,
           const LookAlikeFrames* look_alikes = nullptr) {
    add(performance.truth, performance.times_s, estimates, performance.template_rate_hz,
        look_alikes);
  }
  void merge(const MetricsAccumulator& other);

  Metrics summary() const;
  const MetricsOptions& options() const { return options_; }

 private:
  MetricsOptions options_;
  std::vector<double> errors_ms_;   // scored frames
  std::vector<double> recovery_s_;  // one per jump, +inf when unrecovered
  std::vector<double> find_s_;      // one per performance, +inf when never found
  CalibrationAccumulator calibration_;
  long long frames_ = 0, pause_frames_ = 0, lost_ = 0, misses_ = 0;
  long long tracked_ = 0, lost_on_tracked_ = 0, reported_jumps_ = 0, false_jumps_ = 0;
  long long lost_switches_ = 0;
  long long within_100ms_alike_ = 0;
  long long found_scored_ = 0, found_within_100ms_ = 0;
  double duration_s_ = 0.0;
  double step_us_sum_ = 0.0;
};

// Summary of one performance.
Metrics compute_metrics(const Performance& performance, std::span<const FrameEstimate> estimates,
                        const MetricsOptions& options = {});

}  // namespace duet
