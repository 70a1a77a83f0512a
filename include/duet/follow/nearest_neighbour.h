// Baseline: per-frame nearest neighbour. Each input frame is matched to the closest template frame
// over the whole library, with no memory of the past. O(M * D) per frame.
// The model must outlive the tracker.
#pragma once

#include <span>
#include <string_view>
#include <vector>

#include "duet/base/result.h"
#include "duet/follow/follow_params.h"
#include "duet/follow/template_model.h"
#include "duet/follow/tracker.h"

namespace duet {

class NearestNeighbourTracker final : public Tracker {
 public:
  // Uses emission_sigma (confidence: mass of exp(-d^2 / (2 sigma^2)) around the estimate),
  // lost_distance_per_dim, confidence_window_frames and max_steps_per_frame from params.
  static Result<NearestNeighbourTracker> create(const TemplateModel& model,
                                                const FollowParams& params);

  void reset() noexcept override;
  // A missing frame keeps the previous estimate.
  FollowResult step(std::span<const float> features, double dt_s) noexcept override;
  std::string_view name() const noexcept override { return "nearest_neighbour"; }

 private:
  NearestNeighbourTracker() = default;

  const TemplateModel* model_ = nullptr;
  FollowParams params_;
  float inv_two_sigma_sq_ = 0.0f;
  std::vector<float> distance_sq_;  // M
  FollowResult previous_;
};

}  // namespace duet
