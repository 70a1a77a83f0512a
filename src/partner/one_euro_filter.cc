#include "duet/partner/one_euro_filter.h"

#include <cmath>

#include "duet/math/rotation.h"

namespace duet {
namespace {

// Smoothing factor of an exponential low-pass with this cutoff, for a step of dt_s.
double alpha(double cutoff_hz, double dt_s) {
  const double tau = 1.0 / (2.0 * kPi * cutoff_hz);
  return 1.0 / (1.0 + tau / dt_s);
}

}  // namespace

const char* OneEuroParams::validate() const noexcept {
  if (!(min_cutoff_hz > 0.0) || !std::isfinite(min_cutoff_hz)) return "min_cutoff_hz must be > 0";
  if (!(beta >= 0.0) || !std::isfinite(beta)) return "beta must be >= 0";
  if (!(derivative_cutoff_hz > 0.0) || !std::isfinite(derivative_cutoff_hz)) {
    return "derivative_cutoff_hz must be > 0";
  }
  return "";
}

Vec3 OneEuroFilter3::filter(const Vec3& sample, double dt_s, const OneEuroParams& params) noexcept {
  if (!sample.allFinite()) return value_;
  if (!primed_ || !(dt_s > 0.0) || !std::isfinite(dt_s)) {
    primed_ = true;
    value_ = sample;
    speed_ = Vec3::Zero();
    return value_;
  }
  const Vec3 raw_speed = (sample - value_) / dt_s;
  speed_ += alpha(params.derivative_cutoff_hz, dt_s) * (raw_speed - speed_);
  const double cutoff = params.min_cutoff_hz + params.beta * speed_.norm();
  value_ += alpha(cutoff, dt_s) * (sample - value_);
  return value_;
}

void OneEuroFilter3::rebase(const Quat& rotation, const Vec3& translation) noexcept {
  value_ = rotation * value_ + translation;
  speed_ = rotation * speed_;
}

}  // namespace duet
