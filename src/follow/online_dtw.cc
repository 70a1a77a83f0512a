#include "duet/follow/online_dtw.h"

#include <Eigen/Core>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>

#include "forward_common.h"

namespace duet {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

Result<OnlineDtwTracker> OnlineDtwTracker::create(const TemplateModel& model,
                                                  const OnlineDtwParams& params) {
  auto error = [](const std::string& reason) { return make_error("online DTW", 0, reason); };
  if (params.window_back < 0 || params.window_ahead < 0) {
    return error("window_back and window_ahead must be >= 0");
  }
  if (!(params.emission_sigma >= 1e-3f && std::isfinite(params.emission_sigma))) {
    return error("emission_sigma must be finite and >= 0.001");
  }
  if (!(params.lost_distance_per_dim >= 0.0f)) return error("lost_distance_per_dim must be >= 0");
  if (params.confidence_window_frames < 0) return error("confidence_window_frames must be >= 0");
  if (params.max_steps_per_frame < 1 || params.max_steps_per_frame > 1000) {
    return error("max_steps_per_frame must be in [1, 1000]");
  }
  OnlineDtwTracker tracker;
  tracker.model_ = &model;
  tracker.params_ = params;
  tracker.inv_two_sigma_sq_ = 1.0f / (2.0f * params.emission_sigma * params.emission_sigma);
  const auto size = static_cast<std::size_t>(model.num_states());
  tracker.cost_.assign(size, kInf);
  tracker.next_cost_.assign(size, kInf);
  tracker.distance_sq_.assign(size, 0.0f);
  return tracker;
}

void OnlineDtwTracker::reset() noexcept {
  begin_ = end_ = 0;
  previous_state_ = -1;
  previous_lost_ = false;
}

FollowResult OnlineDtwTracker::step(std::span<const float> features, double dt_s) noexcept {
  const follow_detail::ScopedFlushDenormals flush_denormals;
  const TemplateModel& model = *model_;
  const int num_states = model.num_states();
  FollowResult result;
  result.steps = follow_detail::steps_for(dt_s, model.frame_rate_hz(), params_.max_steps_per_frame);
  assert(features.size() == static_cast<std::size_t>(model.num_dims()));
  result.missing = features.size() != static_cast<std::size_t>(model.num_dims()) ||
                   !follow_detail::all_finite(features);
  const int max_advance = 2 * result.steps;  // the band's slope constraint, per input frame

  // Open begin: the first frame (or a restart) searches the whole library.
  const bool first = begin_ == end_ || previous_state_ < 0;
  const int begin = first ? 0 : std::max(0, previous_state_ - params_.window_back);
  const int end =
      first ? num_states
            : std::min(num_states, previous_state_ + params_.window_ahead + max_advance + 1);
  const int count = end - begin;
  float* local = distance_sq_.data();

  float best_local = 0.0f;
  if (result.missing) {
    std::fill(local, local + count, 0.0f);
  } else {
    best_local =
        follow_detail::squared_distances(model.features(), features.data(), begin, end, local);
  }

  // D_t(j) = d_t(j) + min_{k=0..2n} D_{t-1}(j - k), same take only.
  int take = model.take_of(begin);
  int take_begin = model.take_begin(take);
  int take_end = model.take_end(take);
  int state = -1;
  float best_cost = kInf;
  for (int j = begin; j < end; ++j) {
    if (j >= take_end) {
      ++take;
      take_begin = model.take_begin(take);
      take_end = model.take_end(take);
    }
    float from = 0.0f;
    if (!first) {
      from = kInf;
      const int lowest = std::max({take_begin, begin_, j - max_advance});
      for (int source = std::min(j, end_ - 1); source >= lowest; --source) {
        from = std::min(from, cost_[static_cast<std::size_t>(source)]);
      }
    }
    const float cost = from + local[j - begin];
    next_cost_[static_cast<std::size_t>(j)] = cost;
    if (cost < best_cost) {
      best_cost = cost;
      state = j;
    }
  }
  if (state < 0) {
    // Unreachable (the previous estimate is always its own source); restart to be safe.
    assert(false && "online DTW window lost every path");
    reset();
    return result;
  }
  // Keep the accumulated costs bounded: only differences matter.
  for (int j = begin; j < end; ++j) next_cost_[static_cast<std::size_t>(j)] -= best_cost;
  cost_.swap(next_cost_);
  begin_ = begin;
  end_ = end;

  // Confidence from the current frame alone: softmax of -d^2 / (2 sigma^2) over the window,
  // mass within confidence_window_frames of the estimate (same take, inside the window).
  const int window_take = model.take_of(state);
  const int lo =
      std::max({model.take_begin(window_take), begin, state - params_.confidence_window_frames});
  const int hi =
      std::min({model.take_end(window_take), end, state + params_.confidence_window_frames + 1});
  if (!result.missing) {
    Eigen::Map<Eigen::ArrayXf> weight(local, count);
    weight = ((weight - best_local) * -inv_two_sigma_sq_).max(follow_detail::kMinLogEmission).exp();
    const float total = weight.sum();
    float mass = 0.0f;
    for (int j = lo; j < hi; ++j) mass += local[j - begin];
    result.confidence = std::clamp(mass / total, 0.0f, 1.0f);
    result.best_distance_per_dim = best_local / static_cast<float>(model.num_dims());
    result.log_likelihood = -static_cast<double>(best_local) * inv_two_sigma_sq_;
    result.lost = result.best_distance_per_dim > params_.lost_distance_per_dim;
  } else {
    result.confidence = static_cast<float>(hi - lo) / static_cast<float>(count);
    result.best_distance_per_dim = -1.0f;
    result.lost = previous_lost_;
  }
  result.state = state;
  result.take = window_take;
  result.frame_in_take = state - model.take_begin(window_take);
  result.jumped = model.is_jump(previous_state_, state, result.steps);
  previous_state_ = state;
  previous_lost_ = result.lost;
  return result;
}

}  // namespace duet
