#include "duet/follow/follower_history.h"

namespace duet {

FollowerHistory::FollowerHistory(const TemplateModel& model, const FollowParams& params)
    : sensor_noise(model.num_dims() - model.velocity_dims(), params.sensor_noise_time_constant_s,
                   model.frame_rate_hz()),
      noise_filter(model.num_dims(), model.num_dims() - model.velocity_dims(),
                   params.noise_filter_density, params.noise_filter_allowance,
                   model.frame_rate_hz()) {}

void FollowerHistory::reset() noexcept {
  total_log_likelihood = 0.0;
  frames = 0;
  previous_state = -1;
  previous_lost = false;
  previous_outlier = false;
  lost_by_distance = false;
  ceiling_lost.reset();
  against_s = 0.0;
  tempo.reset();
  jump_gate.reset();
  sensor_noise.reset();
  noise_filter.reset();
  explained_residual.reset();
}

}  // namespace duet
