// Baseline: online dynamic time warping, windowed, open-begin and open-end.
//
// Not Dixon's (2005) full OLTW, which decides per step whether to grow the cost matrix by an
// input row or a template column; here the template is known in advance and every input frame
// adds one row. Accumulated cost over template states j:
//   D_t(j) = d_t(j) + min_{k = 0..2n} D_{t-1}(j - k)     (same take only; n = template steps)
// with d_t(j) = ||phi_t - phi_j||^2, i.e. the HMM band's slope constraint (0 to 2 template frames
// per template-rate step) without probabilities. Every path to row t has exactly t + 1 local
// costs, so no length normalisation is needed. The first frame searches the whole library;
// afterwards only a window [estimate - window_back, estimate + window_ahead + 2n] is updated,
// which makes a step O(window * D) but means the tracker cannot follow a jump outside the window.
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

struct OnlineDtwParams {
  int window_back = 60;    // template frames behind the estimate kept in the search window
  int window_ahead = 120;  // template frames ahead of the estimate (plus 2n)
  // Shared meanings with FollowParams: confidence (softmax of -d^2 / (2 sigma^2) of the current
  // frame), lost threshold, rate handling.
  float emission_sigma = 1.0f;
  float lost_distance_per_dim = 1.0f;
  int confidence_window_frames = 6;
  int max_steps_per_frame = 8;
};

class OnlineDtwTracker final : public Tracker {
 public:
  static Result<OnlineDtwTracker> create(const TemplateModel& model, const OnlineDtwParams& params);

  void reset() noexcept override;
  // A missing frame adds no local cost (the path only advances).
  FollowResult step(std::span<const float> features, double dt_s) noexcept override;
  std::string_view name() const noexcept override { return "online_dtw"; }

 private:
  OnlineDtwTracker() = default;

  const TemplateModel* model_ = nullptr;
  OnlineDtwParams params_;
  float inv_two_sigma_sq_ = 0.0f;
  std::vector<float> cost_, next_cost_;  // accumulated cost D, valid inside [begin_, end_)
  std::vector<float> distance_sq_;       // d_t, valid inside the current window
  int begin_ = 0, end_ = 0;              // window of the previous frame; empty after reset
  int previous_state_ = -1;
  bool previous_lost_ = false;
};

}  // namespace duet
