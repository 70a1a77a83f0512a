#include "duet/follow/tempo_band.h"

#include <algorithm>
#include <cmath>

namespace duet {

float BandProbabilities::mean_advance() const {
  const float sum = total();
  return sum > 0.0f ? (next + 2.0f * skip) / sum : 0.0f;
}

BandProbabilities tilt_band(const BandProbabilities& base, float tempo) {
  const double sum = base.total();
  if (!(sum > 0.0) || !(base.self > 0.0f) || !std::isfinite(tempo)) return base;
  const double s = base.self / sum;
  const double n = base.next / sum;
  const double k = base.skip / sum;
  // The reachable means are (0, 2) with a skip, (0, 1) with only next; stay 1% inside.
  const double reach = k > 0.0 ? 2.0 : (n > 0.0 ? 1.0 : 0.0);
  if (reach == 0.0) return base;
  const double t = std::clamp(static_cast<double>(tempo), 0.01 * reach, 0.99 * reach);

  // a x^2 + b x + c = 0 with a >= 0, c < 0: exactly one positive root.
  const double a = k * (2.0 - t);
  const double b = n * (1.0 - t);
  const double c = -t * s;
  double x = 0.0;
  if (a > 1e-12) {
    // The root with the + sign, written to avoid cancellation when b > 0.
    const double root = std::sqrt(b * b - 4.0 * a * c);
    x = b > 0.0 ? (2.0 * -c) / (b + root) : (-b + root) / (2.0 * a);
  } else if (b > 0.0) {
    x = -c / b;
  }
  if (!(x > 0.0) || !std::isfinite(x)) return base;

  const double w0 = s, w1 = n * x, w2 = k * x * x;
  const double scale = sum / (w0 + w1 + w2);
  return {static_cast<float>(w0 * scale), static_cast<float>(w1 * scale),
          static_cast<float>(w2 * scale)};
}

void TempoEstimator::update(int previous_state, int state, int steps, double dt_s, bool usable,
                            const TempoLimits& limits) noexcept {
  if (!usable || previous_state < 0 || steps < 1 || !(dt_s > 0.0) || !std::isfinite(dt_s)) return;
  const int moved = state - previous_state;
  if (moved < 0 || moved > 2 * steps) return;  // not a band move
  const double rate = static_cast<double>(moved) / steps;
  // An exponential average, but a plain running mean while there are fewer moves than its memory
  // holds, so the first second of a dance already counts fully rather than being pulled to 1.
  ++updates_;
  const double weight =
      std::max(1.0 - std::exp(-dt_s / limits.time_constant_s), 1.0 / (updates_ + 1));
  const double next = tempo_ + weight * (rate - tempo_);
  tempo_ = static_cast<float>(std::clamp(next, double{limits.min_tempo}, double{limits.max_tempo}));
}

void TempoEstimator::observe_rate(int steps, double dt_s, double template_fps,
                                  const TempoLimits& limits) noexcept {
  if (steps < 1 || !(dt_s > 0.0) || !std::isfinite(dt_s) || !(template_fps > 0.0) ||
      !std::isfinite(template_fps)) {
    return;
  }
  const double frames = dt_s * template_fps;
  if (!(mean_template_frames_ > 0.0)) {  // the first frame with a time sets both
    mean_steps_ = steps;
    mean_template_frames_ = frames;
    return;
  }
  // Means of a ratio's two sides, not of the ratio: a late frame (1.4 periods, one step) and the
  // early one after it (0.6, one step) average to one step per template frame.
  const double weight = 1.0 - std::exp(-dt_s / limits.time_constant_s);
  mean_steps_ += weight * (steps - mean_steps_);
  mean_template_frames_ += weight * (frames - mean_template_frames_);
}

float TempoEstimator::dancer_tempo() const noexcept {
  if (!(mean_template_frames_ > 0.0)) return tempo_;
  // At the template's rate or slower one step is one template frame of time; only a sensor
  // faster than the template makes more steps than frames of time.
  const double steps_per_frame = std::max(mean_steps_ / mean_template_frames_, 1.0);
  return static_cast<float>(tempo_ * steps_per_frame);
}

}  // namespace duet
