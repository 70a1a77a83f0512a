#include "duet/follow/sensor_noise.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace duet {

namespace {

// One frame may raise the average at most this many times its current value (plus the floor
// below): a jump of the input to another part of the dance, or a glitch, is one huge residual
// that is no sensor noise.
constexpr double kMaxRise = 4.0;
// Variance per dimension below which a frame is never clipped (a clean sensor's own level).
constexpr double kClipFloor = 1e-3;

}  // namespace

SensorNoiseEstimator::SensorNoiseEstimator(int posture_dims, double time_constant_s,
                                           double template_fps)
    : dims_(std::max(posture_dims, 0)),
      time_constant_s_(time_constant_s > 0.0 ? time_constant_s : 1.0),
      default_dt_s_(template_fps > 0.0 ? 1.0 / template_fps : 1.0 / 60.0),
      previous_(static_cast<std::size_t>(dims_), 0.0f),
      before_(static_cast<std::size_t>(dims_), 0.0f) {}

void SensorNoiseEstimator::reset() noexcept {
  chain_ = 0;
  variance_ = 0.0;
  seen_s_ = 0.0;
  previous_dt_s_ = 0.0;
}

void SensorNoiseEstimator::update(std::span<const float> features, double dt_s,
                                  bool present) noexcept {
  if (dims_ == 0) return;
  if (!present || features.size() < static_cast<std::size_t>(dims_)) {
    chain_ = 0;
    return;
  }
  const double dt = dt_s > 0.0 && std::isfinite(dt_s) ? dt_s : default_dt_s_;
  if (chain_ == 2) {
    const double r = dt / previous_dt_s_;
    double sum = 0.0;
    for (int d = 0; d < dims_; ++d) {
      const auto i = static_cast<std::size_t>(d);
      const double residual = static_cast<double>(features[i]) - previous_[i] -
                              (static_cast<double>(previous_[i]) - before_[i]) * r;
      sum += residual * residual;
    }
    const double gain = 1.0 + (1.0 + r) * (1.0 + r) + r * r;
    double frame = sum / (static_cast<double>(dims_) * gain);
    if (seen_s_ > 0.0) frame = std::min(frame, kMaxRise * variance_ + kClipFloor);
    // A running mean over the first time constant, then an exponential average.
    seen_s_ += dt;
    const double weight = std::min(1.0, dt / std::min(seen_s_, time_constant_s_));
    variance_ += weight * (frame - variance_);
  }
  std::copy_n(previous_.begin(), dims_, before_.begin());
  std::copy_n(features.begin(), dims_, previous_.begin());
  previous_dt_s_ = dt;
  chain_ = std::min(chain_ + 1, 2);
}

}  // namespace duet
