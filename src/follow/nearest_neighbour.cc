#include "duet/follow/nearest_neighbour.h"

#include <Eigen/Core>
#include <cassert>

#include "forward_common.h"

namespace duet {

Result<NearestNeighbourTracker> NearestNeighbourTracker::create(const TemplateModel& model,
                                                                const FollowParams& params) {
  if (Status status = params.validate(model.num_states()); !status.ok()) return status.error();
  NearestNeighbourTracker tracker;
  tracker.model_ = &model;
  tracker.params_ = params;
  tracker.params_.resume_weights.clear();  // unused
  const float sigma = params.emission_sigma;
  tracker.inv_two_sigma_sq_ = 1.0f / (2.0f * sigma * sigma);
  tracker.distance_sq_.assign(static_cast<std::size_t>(model.num_states()), 0.0f);
  return tracker;
}

void NearestNeighbourTracker::reset() noexcept { previous_ = FollowResult{}; }

FollowResult NearestNeighbourTracker::step(std::span<const float> features, double dt_s) noexcept {
  const follow_detail::ScopedFlushDenormals flush_denormals;
  const TemplateModel& model = *model_;
  const int num_states = model.num_states();
  const int steps =
      follow_detail::steps_for(dt_s, model.frame_rate_hz(), params_.max_steps_per_frame);
  assert(features.size() == static_cast<std::size_t>(model.num_dims()));
  if (features.size() != static_cast<std::size_t>(model.num_dims()) ||
      !follow_detail::all_finite(features)) {
    FollowResult result = previous_;
    result.missing = true;
    result.jumped = false;
    result.steps = steps;
    result.log_likelihood = 0.0;
    result.best_distance_per_dim = -1.0f;
    return result;
  }

  FollowResult result;
  result.steps = steps;
  const float best = follow_detail::squared_distances(model.features(), features.data(), 0,
                                                      num_states, distance_sq_.data());
  result.best_distance_per_dim = best / static_cast<float>(model.num_dims());
  result.log_likelihood = -static_cast<double>(best) * inv_two_sigma_sq_;
  result.lost = result.best_distance_per_dim > params_.lost_distance_per_dim;
  // Confidence: the frame's own posterior under a uniform prior, softmax of -d^2 / (2 sigma^2).
  Eigen::Map<Eigen::ArrayXf> weight(distance_sq_.data(), num_states);
  weight = ((weight - best) * -inv_two_sigma_sq_).max(follow_detail::kMinLogEmission).exp();
  follow_detail::decide(model, distance_sq_.data(), weight.sum(), 0.0f, previous_.state, steps,
                        params_.confidence_window_frames, result);
  previous_ = result;
  return result;
}

}  // namespace duet
