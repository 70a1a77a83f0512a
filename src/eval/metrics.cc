#include "duet/eval/metrics.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <utility>

#include "duet/eval/look_alike_frames.h"

namespace duet {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kLastJumpMargin_s = 1.0;

// Median of values (sorted copy); the mean of the two middle values for an even count.
double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::ranges::sort(values);
  const std::size_t n = values.size();
  if (n % 2 == 1) return values[n / 2];
  const double a = values[n / 2 - 1], b = values[n / 2];
  return std::isinf(a) || std::isinf(b) ? kInf : 0.5 * (a + b);
}

// The first scored frame from which every scored frame's error stays within tolerance_ms for
// hold_s (pause frames neither break nor count), or errors.size() when there is none. truth and
// times_s have at least as many frames as errors.
std::size_t first_found_frame(std::span<const TruthFrame> truth, std::span<const double> times_s,
                              std::span<const double> errors, double tolerance_ms, double hold_s) {
  const std::size_t n = errors.size();
  std::size_t start = n;
  for (std::size_t i = 0; i < n; ++i) {
    if (truth[i].in_pause) continue;
    if (errors[i] > tolerance_ms) {
      start = n;
      continue;
    }
    if (start == n) start = i;
    if (times_s[i] - times_s[start] >= hold_s) return start;
  }
  return n;
}

}  // namespace

FrameEstimate frame_estimate(const FollowResult& r, double step_us) {
  FrameEstimate e;
  e.take = r.take;
  e.frame_in_take = r.frame_in_take;
  e.frame_offset = r.frame_offset;
  e.lost = r.lost;
  e.jumped = r.jumped;
  e.confidence = r.confidence;
  e.window_mass = r.window_mass;
  e.best_distance_per_dim = r.best_distance_per_dim;
  e.sensor_noise_per_dim = r.sensor_noise_per_dim;
  e.rig_offset = r.rig_offset;
  e.rig_offset_learnt_s = r.rig_offset_learnt_s;
  e.tracker_confidence = r.tracker_confidence;
  e.in_pause = r.in_pause;
  e.outlier = r.outlier;
  e.step_us = step_us;
  return e;
}

double frame_error_ms(const TruthFrame& truth, const FrameEstimate& estimate,
                      double template_rate_hz, const MetricsOptions& options) {
  if (estimate.take < 0 || estimate.take != truth.take) return options.miss_error_ms;
  const double error =
      std::abs(estimate.frame_in_take - truth.template_frame) / template_rate_hz * 1000.0;
  return std::min(error, options.miss_error_ms);
}

void MetricsAccumulator::add(std::span<const TruthFrame> truth, std::span<const double> times_s,
                             std::span<const FrameEstimate> estimates, double template_rate_hz,
                             const LookAlikeFrames* look_alikes) {
  assert(truth.size() == times_s.size() && truth.size() == estimates.size());
  const std::size_t n = std::min({truth.size(), times_s.size(), estimates.size()});
  std::vector<double> errors(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    ++frames_;
    step_us_sum_ += estimates[i].step_us;
    if (truth[i].in_pause) {
      ++pause_frames_;
      continue;
    }
    errors[i] = frame_error_ms(truth[i], estimates[i], template_rate_hz, options_);
    errors_ms_.push_back(errors[i]);
    if (estimates[i].take < 0 || estimates[i].take != truth[i].take) ++misses_;
    if (estimates[i].lost) ++lost_;
    calibration_.add(estimates[i].confidence, errors[i] <= 100.0);
    if (errors[i] <= 100.0 ||
        (look_alikes != nullptr && look_alikes->shows_the_same(truth[i], estimates[i]))) {
      ++within_100ms_alike_;
    }
    if (errors[i] <= 100.0) {
      ++tracked_;
      if (estimates[i].lost) ++lost_on_tracked_;
    }
  }
  if (n > 1) duration_s_ += times_s[n - 1] - times_s[0];
  for (std::size_t i = 1; i < n; ++i) lost_switches_ += estimates[i].lost != estimates[i - 1].lost;

  // Reported jumps that answer no true jump: outside every window that opens just before a true
  // jump's pause (or the jump) and closes jump_answer_window_s after the jump.
  std::vector<std::pair<double, double>> answer_windows;
  for (std::size_t k = 0; k < n; ++k) {
    if (!truth[k].jump) continue;
    std::size_t first = k;
    while (first > 0 && truth[first - 1].in_pause) --first;
    answer_windows.emplace_back(times_s[first] - options_.jump_answer_lead_s,
                                times_s[k] + options_.jump_answer_window_s);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!estimates[i].jumped) continue;
    ++reported_jumps_;
    const bool answers = std::ranges::any_of(answer_windows, [&](const auto& w) {
      return times_s[i] >= w.first && times_s[i] <= w.second;
    });
    if (!answers) ++false_jumps_;
  }

  // Finding the dance (Metrics::median_find_s).
  if (n > 0) {
    const std::size_t found = first_found_frame(
        truth, times_s, errors, options_.recovery_tolerance_ms, options_.find_hold_s);
    find_s_.push_back(found < n ? times_s[found] - times_s[0] : kInf);
    for (std::size_t i = found; i < n; ++i) {
      if (truth[i].in_pause) continue;
      ++found_scored_;
      if (errors[i] <= 100.0) ++found_within_100ms_;
    }
  }

  // Jump recovery: first frame after the jump from which the error stays within tolerance for
  // the hold time (and at least 3 frames), before the next pause or jump.
  const double tolerance = options_.recovery_tolerance_ms;
  for (std::size_t k = 0; k < n; ++k) {
    if (!truth[k].jump || truth[k].in_pause) continue;
    std::size_t end = k + 1;
    while (end < n && !truth[end].jump && !truth[end].in_pause) ++end;
    // A jump too close to the end of the performance has no time to be recovered: not counted.
    if (end == n && times_s[n - 1] - times_s[k] < kLastJumpMargin_s) continue;
    double recovery = kInf;
    for (std::size_t j = k; j < end; ++j) {
      if (errors[j] > tolerance) continue;
      const auto in_hold = [&](std::size_t i) {
        return i - j < 3 || times_s[i] - times_s[j] < options_.recovery_hold_s;
      };
      std::size_t i = j;
      while (i < end && in_hold(i) && errors[i] <= tolerance) ++i;
      if (i >= end) break;  // the hold does not fit before the next pause or jump
      if (in_hold(i)) {     // frame i broke the hold; no start before it can pass it
        j = i;
        continue;
      }
      recovery = times_s[j] - times_s[k];
      break;
    }
    recovery_s_.push_back(recovery);
  }
}

void MetricsAccumulator::merge(const MetricsAccumulator& other) {
  errors_ms_.insert(errors_ms_.end(), other.errors_ms_.begin(), other.errors_ms_.end());
  recovery_s_.insert(recovery_s_.end(), other.recovery_s_.begin(), other.recovery_s_.end());
  find_s_.insert(find_s_.end(), other.find_s_.begin(), other.find_s_.end());
  found_scored_ += other.found_scored_;
  found_within_100ms_ += other.found_within_100ms_;
  calibration_.merge(other.calibration_);
  frames_ += other.frames_;
  pause_frames_ += other.pause_frames_;
  lost_ += other.lost_;
  misses_ += other.misses_;
  tracked_ += other.tracked_;
  lost_on_tracked_ += other.lost_on_tracked_;
  lost_switches_ += other.lost_switches_;
  within_100ms_alike_ += other.within_100ms_alike_;
  reported_jumps_ += other.reported_jumps_;
  false_jumps_ += other.false_jumps_;
  duration_s_ += other.duration_s_;
  step_us_sum_ += other.step_us_sum_;
}

Metrics MetricsAccumulator::summary() const {
  Metrics m;
  m.frames = frames_;
  m.pause_frames = pause_frames_;
  m.scored_frames = static_cast<long long>(errors_ms_.size());
  if (m.scored_frames > 0) {
    long long w50 = 0, w100 = 0, w300 = 0;
    double sum = 0.0;
    for (const double e : errors_ms_) {
      w50 += e <= 50.0 ? 1 : 0;
      w100 += e <= 100.0 ? 1 : 0;
      w300 += e <= 300.0 ? 1 : 0;
      sum += e;
    }
    const auto scored = static_cast<double>(m.scored_frames);
    m.within_50ms = static_cast<double>(w50) / scored;
    m.within_100ms = static_cast<double>(w100) / scored;
    m.within_300ms = static_cast<double>(w300) / scored;
    m.within_100ms_alike = static_cast<double>(within_100ms_alike_) / scored;
    m.miss_fraction = static_cast<double>(misses_) / scored;
    m.mean_error_ms = sum / scored;
    m.median_error_ms = median(errors_ms_);
    m.lost_fraction = static_cast<double>(lost_) / scored;
  }
  m.lost_on_tracked_fraction =
      tracked_ > 0 ? static_cast<double>(lost_on_tracked_) / static_cast<double>(tracked_) : 0.0;
  m.reported_jumps = reported_jumps_;
  m.false_jumps = false_jumps_;
  m.false_jumps_per_minute =
      duration_s_ > 0.0 ? static_cast<double>(false_jumps_) / (duration_s_ / 60.0) : 0.0;
  m.lost_switches_per_minute =
      duration_s_ > 0.0 ? static_cast<double>(lost_switches_) / (duration_s_ / 60.0) : 0.0;
  m.jumps = static_cast<long long>(recovery_s_.size());
  double recovered_sum = 0.0;
  for (const double r : recovery_s_) {
    if (std::isinf(r)) continue;
    ++m.recovered_jumps;
    recovered_sum += r;
  }
  m.median_recovery_s = median(recovery_s_);
  m.mean_recovery_s =
      m.recovered_jumps > 0 ? recovered_sum / static_cast<double>(m.recovered_jumps) : 0.0;
  m.median_find_s = median(find_s_);
  m.worst_find_s = find_s_.empty() ? 0.0 : std::ranges::max(find_s_);
  m.within_100ms_found = found_scored_ > 0 ? static_cast<double>(found_within_100ms_) /
                                                 static_cast<double>(found_scored_)
                                           : 0.0;
  m.mean_step_us = frames_ > 0 ? step_us_sum_ / static_cast<double>(frames_) : 0.0;
  m.confidence_ece = calibration_.expected_calibration_error();
  m.reliability = calibration_.diagram();
  return m;
}

Metrics compute_metrics(const Performance& performance, std::span<const FrameEstimate> estimates,
                        const MetricsOptions& options) {
  MetricsAccumulator accumulator(options);
  accumulator.add(performance, estimates);
  return accumulator.summary();
}

}  // namespace duet
