#include "duet/follow/template_model.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

namespace duet {

float TemplateModel::held_precision(float value) {
  constexpr float kLargestHalf = 65504.0f;
  if (!std::isfinite(value)) return value;  // for build to refuse
  return static_cast<float>(Eigen::half(std::clamp(value, -kLargestHalf, kLargestHalf)));
}

namespace {

// held_precision(value) == value, from the value itself rather than a round trip through a half:
// build_shared checks every feature of a mapped cache at start-up with it (at 1M states the
// start-up takes 212 ms without the check, 280 with this one, 405 with the round trip).
bool at_held_precision(float value) {
  const float magnitude = std::abs(value);
  if (!(magnitude <= 65504.0f)) return false;  // beyond the largest half, infinite or NaN
  if (magnitude >= 0x1p-14f) {
    // A normal half: 10 bits of mantissa, the float's last 13 zero.
    return (std::bit_cast<std::uint32_t>(value) & 0x1fffu) == 0;
  }
  const float in_smallest_steps = magnitude * 0x1p24f;  // a subnormal half: a multiple of 2^-24
  return in_smallest_steps == std::trunc(in_smallest_steps);
}

Error model_error(const std::string& reason) { return make_error("template model", 0, reason); }

// The layout of TemplateModel::blocked_features(): dimension d of the row at blocked_dim
// position[d] (empty: d).
std::vector<std::uint16_t> blocked(const FeatureView& features,
                                   const std::vector<int>& position = {}) {
  constexpr Eigen::Index kBlock = TemplateModel::kStateBlock;
  const Eigen::Index rows = features.rows();
  const Eigen::Index dims = features.cols();
  const Eigen::Index blocks = (rows + kBlock - 1) / kBlock;
  std::vector<std::uint16_t> out(static_cast<std::size_t>(blocks * dims * kBlock), 0);  // +0
  for (Eigen::Index i = 0; i < rows; ++i) {
    const Eigen::Index b = i / kBlock;
    const Eigen::Index lane = i % kBlock;
    for (Eigen::Index d = 0; d < dims; ++d) {
      const Eigen::Index at = position.empty() ? d : position[static_cast<std::size_t>(d)];
      out[static_cast<std::size_t>((b * dims + at) * kBlock + lane)] =
          Eigen::numext::bit_cast<std::uint16_t>(Eigen::half(features(i, d)));
    }
  }
  return out;
}

// A row-major buffer of num_frames x num_dims features: both positive and the sizes agreeing.
Status check_buffer(std::span<const float> features_row_major, int num_frames, int num_dims) {
  if (num_frames <= 0 || num_dims <= 0) {
    return model_error("no template features (" + std::to_string(num_frames) + " frames x " +
                       std::to_string(num_dims) + " dimensions)");
  }
  const auto expected = static_cast<std::size_t>(num_frames) * static_cast<std::size_t>(num_dims);
  if (features_row_major.size() != expected) {
    return model_error("feature buffer holds " + std::to_string(features_row_major.size()) +
                       " values, expected " + std::to_string(num_frames) + " frames x " +
                       std::to_string(num_dims) + " dimensions = " + std::to_string(expected));
  }
  return Ok{};
}

}  // namespace

Result<TemplateModel> TemplateModel::build(FeatureMatrix features, std::vector<int> take_start,
                                           double frame_rate_hz, int velocity_dims) {
  const Eigen::Index num_frames = features.rows();
  const Eigen::Index num_dims = features.cols();
  if (num_frames >= (Eigen::Index{1} << 30) || num_dims >= (Eigen::Index{1} << 20)) {
    return model_error("too many template frames or dimensions: " + std::to_string(num_frames) +
                       " x " + std::to_string(num_dims));
  }
  features = features.unaryExpr(&held_precision);
  auto owned = std::make_shared<const FeatureMatrix>(std::move(features));
  std::shared_ptr<const float> data(owned, owned->data());
  return finish(std::move(data), static_cast<int>(num_frames), static_cast<int>(num_dims),
                std::move(take_start), frame_rate_hz, velocity_dims);
}

Result<TemplateModel> TemplateModel::build(std::span<const float> features_row_major,
                                           int num_frames, int num_dims,
                                           std::vector<int> take_start, double frame_rate_hz,
                                           int velocity_dims) {
  if (Status s = check_buffer(features_row_major, num_frames, num_dims); !s) return s.error();
  FeatureMatrix features =
      Eigen::Map<const FeatureMatrix>(features_row_major.data(), num_frames, num_dims);
  return build(std::move(features), std::move(take_start), frame_rate_hz, velocity_dims);
}

Result<TemplateModel> TemplateModel::build_shared(std::shared_ptr<const void> storage,
                                                  std::span<const float> features_row_major,
                                                  int num_frames, int num_dims,
                                                  std::vector<int> take_start, double frame_rate_hz,
                                                  int velocity_dims) {
  if (Status s = check_buffer(features_row_major, num_frames, num_dims); !s) return s.error();
  const bool held =
      std::all_of(features_row_major.begin(), features_row_major.end(), at_held_precision);
  if (!held) {
    return build(features_row_major, num_frames, num_dims, std::move(take_start), frame_rate_hz,
                 velocity_dims);
  }
  std::shared_ptr<const float> data(std::move(storage), features_row_major.data());
  return finish(std::move(data), num_frames, num_dims, std::move(take_start), frame_rate_hz,
                velocity_dims);
}

Result<TemplateModel> TemplateModel::finish(std::shared_ptr<const float> data, int num_frames,
                                            int num_dims, std::vector<int> take_start,
                                            double frame_rate_hz, int velocity_dims) {
  if (num_frames == 0 || num_dims == 0) {
    return model_error("no template features (" + std::to_string(num_frames) + " frames x " +
                       std::to_string(num_dims) + " dimensions)");
  }
  if (num_frames >= (1 << 30)) {
    return model_error("too many template frames: " + std::to_string(num_frames));
  }
  if (velocity_dims < 0 || velocity_dims > num_dims) {
    return model_error("velocity_dims must be in [0, " + std::to_string(num_dims) + "], got " +
                       std::to_string(velocity_dims));
  }
  if (!std::isfinite(frame_rate_hz) || frame_rate_hz <= 0.0) {
    return model_error("frame rate must be positive, got " + std::to_string(frame_rate_hz));
  }
  const FeatureView features(data.get(), num_frames, num_dims);
  for (Eigen::Index i = 0; i < num_frames; ++i) {
    for (Eigen::Index d = 0; d < num_dims; ++d) {
      if (!std::isfinite(features(i, d))) {
        return model_error("feature " + std::to_string(d) + " of template frame " +
                           std::to_string(i) + " is not finite");
      }
    }
  }
  if (take_start.empty()) take_start.push_back(0);
  if (take_start.front() != 0) {
    return model_error("the first take must start at state 0, got " +
                       std::to_string(take_start.front()));
  }
  for (std::size_t k = 0; k < take_start.size(); ++k) {
    if (take_start[k] >= num_frames) {
      return model_error("take " + std::to_string(k) + " starts at state " +
                         std::to_string(take_start[k]) + ", past the last of " +
                         std::to_string(num_frames) + " template frames");
    }
    if (k > 0 && take_start[k] <= take_start[k - 1]) {
      return model_error("take starts must be strictly increasing: take " + std::to_string(k) +
                         " starts at " + std::to_string(take_start[k]) + ", take " +
                         std::to_string(k - 1) + " at " + std::to_string(take_start[k - 1]));
    }
  }
  take_start.push_back(num_frames);

  TemplateModel model;
  model.blocked_features_ = blocked(features);
  model.features_ = std::move(data);
  model.num_states_ = num_frames;
  model.num_dims_ = num_dims;
  model.take_start_ = std::move(take_start);
  model.frame_rate_hz_ = frame_rate_hz;
  model.velocity_dims_ = velocity_dims;
  return model;
}

Status TemplateModel::set_limbs(std::vector<std::vector<int>> limbs) {
  const int posture = num_dims_ - velocity_dims_;
  if (!limbs.empty() && num_dims_ > kMaxLimbModelDims) {
    return model_error("limbs need a model of at most " + std::to_string(kMaxLimbModelDims) +
                       " dimensions, this one has " + std::to_string(num_dims_));
  }
  std::vector<bool> in_limb(static_cast<std::size_t>(posture), false);
  for (std::size_t limb = 0; limb < limbs.size(); ++limb) {
    for (const int dim : limbs[limb]) {
      if (dim < 0 || dim >= posture) {
        return model_error("limb " + std::to_string(limb) + " names dimension " +
                           std::to_string(dim) + ", outside the " + std::to_string(posture) +
                           " posture dimensions");
      }
      if (in_limb[static_cast<std::size_t>(dim)]) {
        return model_error("dimension " + std::to_string(dim) + " is in two limbs");
      }
      in_limb[static_cast<std::size_t>(dim)] = true;
    }
  }
  std::vector<int> outside_limbs;
  for (int dim = 0; dim < posture; ++dim) {
    if (!in_limb[static_cast<std::size_t>(dim)]) outside_limbs.push_back(dim);
  }
  limbs_ = std::move(limbs);
  // The blocked features in the limbs' order, each group's dimensions contiguous for the SIMD
  // kernel: the dimensions in no limb, then each limb's, then the velocities.
  blocked_position_.assign(static_cast<std::size_t>(num_dims_), 0);
  limb_blocks_.clear();
  int at = 0;
  for (const int dim : outside_limbs) blocked_position_[static_cast<std::size_t>(dim)] = at++;
  for (const std::vector<int>& limb : limbs_) {
    const int begin = at;
    for (const int dim : limb) blocked_position_[static_cast<std::size_t>(dim)] = at++;
    limb_blocks_.push_back({begin, at});
  }
  for (int dim = posture; dim < num_dims_; ++dim) {
    blocked_position_[static_cast<std::size_t>(dim)] = at++;
  }
  if (limbs_.empty()) blocked_position_.clear();
  blocked_features_ = blocked(features(), blocked_position_);
  return Ok{};
}

int TemplateModel::take_of(int state) const {
  assert(state >= 0 && state < num_states());
  // take_start_ is sorted and ends with M: the take is the last start <= state.
  const auto it = std::upper_bound(take_start_.begin(), take_start_.end(), state);
  return static_cast<int>(it - take_start_.begin()) - 1;
}

bool TemplateModel::is_jump(int from, int to, int steps, int tolerance) const noexcept {
  if (from < 0 || to < 0) return false;
  const int moved = to - from;
  if (moved < -tolerance || moved > band_reach(steps) + tolerance) return true;
  return take_of(from) != take_of(to);
}

}  // namespace duet
