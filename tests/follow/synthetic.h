// Synthetic templates and performances for the follow tests: smooth random walks in D dimensions
// with per-frame noise (no two frames alike), standardised per dimension like real features.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include "duet/follow/template_model.h"

namespace duet::test {

// One take: per dimension a damped oscillator driven by noise (a smooth, quasi-periodic random
// walk with a period of about 1.5 s at 60 fps), like a joint angle in a dance.
inline FeatureMatrix smooth_walk(int frames, int dims, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  FeatureMatrix f(frames, dims);
  for (int d = 0; d < dims; ++d) {
    float x = normal(rng), v = 0.0f;
    for (int t = 0; t < frames; ++t) {
      v = 0.95f * v - 0.005f * x + 0.05f * normal(rng);
      x += v;
      f(t, d) = x;
    }
  }
  return f;
}

// Takes of the given lengths, each its own walk, standardised together (unit variance per dim),
// plus white noise of 0.03 so that no two frames are alike. With D = 60, neighbouring frames are
// about 0.45 apart in squared distance, frames 6 apart (100 ms) about 11, frames 30 apart about
// 130 (decorrelated: 2 D).
// velocity_dims: how many trailing dimensions the model treats as velocities (capped distance).
inline TemplateModel make_model(const std::vector<int>& take_lengths, int dims, unsigned seed,
                                double fps = 60.0, int velocity_dims = 0) {
  int total = 0;
  std::vector<int> starts;
  for (const int n : take_lengths) {
    starts.push_back(total);
    total += n;
  }
  FeatureMatrix f(total, dims);
  for (std::size_t k = 0; k < take_lengths.size(); ++k) {
    f.middleRows(starts[k], take_lengths[k]) =
        smooth_walk(take_lengths[k], dims, seed * 7919u + static_cast<unsigned>(k));
  }
  const Eigen::RowVectorXf mean = f.colwise().mean();
  f.rowwise() -= mean;
  for (int d = 0; d < dims; ++d) {
    const float sd = std::sqrt(f.col(d).squaredNorm() / static_cast<float>(total));
    f.col(d) /= std::max(sd, 1e-6f);
  }
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 0.03f);
  for (Eigen::Index i = 0; i < f.size(); ++i) f.data()[i] += noise(rng);
  return std::move(TemplateModel::build(std::move(f), starts, fps, velocity_dims)).value();
}

// Two takes of 100 frames at 60 Hz, every frame unlike every other (frame i's one feature is i):
// for tests of what is decided from a posterior, where the features only tell places apart.
inline TemplateModel two_ramp_takes() {
  FeatureMatrix f = FeatureMatrix::Zero(200, 2);
  for (int i = 0; i < 200; ++i) f(i, 0) = static_cast<float>(i);
  return std::move(TemplateModel::build(std::move(f), {0, 100}, 60.0, 0)).value();
}

// Features at fractional template position `position` (global state index), linearly
// interpolated within its take (clamped to the take's last frame).
inline std::vector<float> features_at(const TemplateModel& model, double position) {
  const int i0 = std::clamp(static_cast<int>(std::floor(position)), 0, model.num_states() - 1);
  const int end = model.take_end(model.take_of(i0));
  const int i1 = std::min(i0 + 1, end - 1);
  const float w = static_cast<float>(std::clamp(position - i0, 0.0, 1.0));
  std::vector<float> out(static_cast<std::size_t>(model.num_dims()));
  for (int d = 0; d < model.num_dims(); ++d) {
    out[static_cast<std::size_t>(d)] =
        (1.0f - w) * model.features()(i0, d) + w * model.features()(i1, d);
  }
  return out;
}

inline void add_noise(std::vector<float>& v, float sd, std::mt19937& rng) {
  std::normal_distribution<float> normal(0.0f, sd);
  for (float& x : v) x += normal(rng);
}

inline bool all_finite(std::span<const float> v) {
  return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
}

}  // namespace duet::test
