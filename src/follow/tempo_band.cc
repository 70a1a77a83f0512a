#include "duet/follow/tempo_band.h"

#include <algorithm>
#include <cmath>

namespace duet {

namespace {
// The start-up averages count at most this many frames: past a few hundred the exponential
// weight is the larger anyway, and a count that keeps growing would overflow in a long session.
constexpr int kMaxCounted = 1 << 20;
}  // namespace

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
  if (!(dt_s > 0.0) || !std::isfinite(dt_s) || steps < 1) return;
  const bool windowed = limits.hold_window_s > 0.0;
  if (!usable || previous_state < 0) {
    // A jump, a lost or missing frame ends the window: judged if long enough to tell a hold.
    if (windowed) settle_window(pending_s_ >= 0.5 * limits.hold_window_s, limits);
    return;
  }
  const int moved = state - previous_state;
  const bool band_move = moved >= 0 && moved <= 2 * steps;
  if (!windowed) {
    if (band_move) teach(moved, steps, dt_s, limits);
    return;
  }
  // Taught at once; undone below if the window it opens turns out to be a hold.
  if (pending_count_ == kMaxPending) forget_oldest();
  PendingMove move;
  move.moved = moved;
  move.dt_s = dt_s;
  // The dancer's tempo, not the steps': a sensor faster than the template makes a step per frame.
  const double template_frames =
      limits.template_fps > 0.0 ? dt_s * limits.template_fps : static_cast<double>(steps);
  move.template_frames = template_frames;
  move.within_reach = moved >= -2 * steps && moved <= 2 * steps;
  move.tempo_before = tempo_;
  move.updates_before = updates_;
  if (band_move) teach(moved, steps, dt_s, limits);
  pending_[static_cast<std::size_t>((pending_first_ + pending_count_) % kMaxPending)] = move;
  ++pending_count_;
  pending_s_ += dt_s;
  if (move.within_reach) {
    pending_moved_ += moved;
    pending_frames_ += template_frames;
  }
  if (pending_s_ < limits.hold_window_s) return;
  if (!is_hold(limits)) {
    held_s_ = 0.0;
  } else if (held_s_ + pending_s_ <= limits.hold_max_s) {
    held_s_ += pending_s_;
    settle_window(true, limits);
    return;
  } else {
    held_s_ += dt_s;  // standing this long is no dancer's hold: the tempo falls again
  }
  // What left the window stands.
  while (pending_count_ > 0 &&
         pending_s_ - pending_[static_cast<std::size_t>(pending_first_)].dt_s >=
             limits.hold_window_s) {
    forget_oldest();
  }
}

bool TempoEstimator::is_hold(const TempoLimits& limits) const noexcept {
  return pending_frames_ > 0.0 &&
         static_cast<double>(pending_moved_) < double{limits.hold_advance} * pending_frames_;
}

void TempoEstimator::settle_window(bool judge, const TempoLimits& limits) noexcept {
  if (pending_count_ > 0 && judge && is_hold(limits)) {
    const PendingMove& first = pending_[static_cast<std::size_t>(pending_first_)];
    tempo_ = first.tempo_before;
    updates_ = first.updates_before;
  }
  pending_first_ = 0;
  pending_count_ = 0;
  pending_s_ = 0.0;
  pending_moved_ = 0;
  pending_frames_ = 0.0;
}

void TempoEstimator::forget_oldest() noexcept {
  const PendingMove& oldest = pending_[static_cast<std::size_t>(pending_first_)];
  if (oldest.within_reach) {
    pending_moved_ -= oldest.moved;
    pending_frames_ -= oldest.template_frames;
  }
  pending_s_ -= oldest.dt_s;
  pending_first_ = (pending_first_ + 1) % kMaxPending;
  --pending_count_;
}

void TempoEstimator::teach(int moved, int steps, double dt_s, const TempoLimits& limits) noexcept {
  const double rate = static_cast<double>(moved) / steps;
  // An exponential average, but a plain running mean while there are fewer moves than its memory
  // holds, so the first second of a dance already counts fully rather than being pulled to 1.
  updates_ = std::min(updates_ + 1, kMaxCounted);
  const double weight =
      std::max(1.0 - std::exp(-dt_s / limits.time_constant_s), 1.0 / (updates_ + 1));
  const double next = tempo_ + weight * (rate - tempo_);
  // The floor is the slowest dancer's tempo, so per step it falls with the steps a template
  // frame of time takes: a 240 Hz sensor's template tempo is 0.25 a step, under the 0.4 a 60 Hz
  // step may take (a floor per step held every dancer at 1.6x or faster). The ceiling is what the
  // band reaches in a step: a faster sensor follows a faster motion (a 60 Hz file read at 120 fps
  // moves 2x, which `duet follow` names by its rate).
  tempo_ = static_cast<float>(
      std::clamp(next, limits.min_tempo / steps_per_template_frame(), double{limits.max_tempo}));
}

void TempoEstimator::observe_rate(int steps, double dt_s, double template_fps,
                                  const TempoLimits& limits) noexcept {
  if (steps < 1 || !(dt_s > 0.0) || !std::isfinite(dt_s) || !(template_fps > 0.0) ||
      !std::isfinite(template_fps)) {
    return;
  }
  const double frames = dt_s * template_fps;
  // Means of a ratio's two sides, not of the ratio: a late frame (1.4 periods, one step) and the
  // early one after it (0.6, one step) average to one step per template frame. A plain running
  // mean over the first frames (with the prior's), as in teach(): when the first frame set both,
  // a first frame 0.1 ms after the one before read as a sensor 166 times faster than the
  // template for seconds, the reported tempo and the tempo's range with it.
  rate_frames_ = std::min(rate_frames_ + 1, kMaxCounted);
  const double weight =
      std::max(1.0 - std::exp(-dt_s / limits.time_constant_s), 1.0 / rate_frames_);
  mean_steps_ += weight * (steps - mean_steps_);
  mean_template_frames_ += weight * (frames - mean_template_frames_);
}

void TempoEstimator::start_at_template_tempo(const TempoLimits& limits) noexcept {
  // Until a move is taught the estimate is the prior that the dancer moves at the template's
  // tempo, in steps: half a frame a step from a 120 Hz sensor on a 60 Hz template. At 1 a step it
  // ran ahead through a standing start, until a hold there happened to drag it down.
  if (updates_ > 0) return;
  tempo_ = static_cast<float>(std::clamp(1.0 / steps_per_template_frame(),
                                         limits.min_tempo / steps_per_template_frame(),
                                         double{limits.max_tempo}));
}

float TempoEstimator::dancer_tempo() const noexcept {
  return static_cast<float>(tempo_ * steps_per_template_frame());
}

double TempoEstimator::steps_per_template_frame() const noexcept {
  // At the template's rate or slower one step is one template frame of time; only a sensor
  // faster than the template makes more steps than frames of time.
  return std::max(mean_steps_ / mean_template_frames_, 1.0);
}

}  // namespace duet
