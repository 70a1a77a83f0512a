#include "forward_common.h"

#include <Eigen/Core>
#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>

#include "duet/follow/copy_places.h"
#include "duet/follow/simd.h"
#include "kernels_avx2.h"
#include "kernels_portable.h"

namespace duet::follow_detail {
namespace {

using ArrayMap = Eigen::Map<Eigen::ArrayXf>;
using ConstArrayMap = Eigen::Map<const Eigen::ArrayXf>;

// Below this the fast path's normaliser has lost too many bits (float normals end at 1.2e-38).
constexpr double kMinNormaliser = 1e-30;

}  // namespace

bool all_finite(std::span<const float> values) noexcept {
  // x - x is 0 for finite x and NaN for inf or NaN; one pass, vectorised.
  float acc = 0.0f;
  for (const float v : values) acc += v - v;
  return acc == 0.0f;
}

int steps_for(double dt_s, double template_fps, int max_steps) noexcept {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) return 1;
  const double n = std::round(dt_s * template_fps);
  if (!(n >= 1.0)) return 1;
  if (n >= static_cast<double>(max_steps)) return max_steps;
  return static_cast<int>(n);
}

float squared_distances(const FeatureView& features, const float* phi, int begin, int end,
                        float* out) noexcept {
  const Eigen::Index dims = features.cols();
  const Eigen::Map<const Eigen::RowVectorXf> query(phi, dims);
  float best = FLT_MAX;
  // Rows are contiguous (row-major), so each distance is one vectorised reduction over D floats.
  for (int i = begin; i < end; ++i) {
    float d2 = (features.row(i) - query).squaredNorm();
    d2 = std::min(d2, FLT_MAX);  // inf (overflow) saturates; NaN is impossible for finite input
    out[i - begin] = d2;
    best = std::min(best, d2);
  }
  return best;
}

DistanceCaps emission_caps(const FollowParams& params) noexcept {
  return {params.velocity_distance_cap, params.limb_outlier_ratio, params.limb_outlier_floor};
}

namespace {

bool nothing_capped(const TemplateModel& model, DistanceCaps caps) noexcept {
  return (model.velocity_dims() == 0 || !(caps.velocity < FLT_MAX)) && !limbs_bounded(model, caps);
}

}  // namespace

EmissionDistance emission_distances(const TemplateModel& model, const float* phi, DistanceCaps caps,
                                    float* out) noexcept {
  const int num_states = model.num_states();
#if defined(__x86_64__)
  if (simd_level() == SimdLevel::kAvx2) {
    return avx2::emission_distances(model, caps, phi, out);
  }
#endif
  if (nothing_capped(model, caps)) {
    const float best = squared_distances(model.features(), phi, 0, num_states, out);
    return {best, best};
  }
  return portable::emission_distances(model, caps, phi, out);
}

EmissionDistance state_emission_distance(const TemplateModel& model, const float* phi, int i,
                                         DistanceCaps caps) noexcept {
  // From the blocked copy, not the row-major features: those may stay in a model cache's map,
  // and a beam's scattered states would page them in (docs/follower.md, "Start-up"). The groups
  // and the order of the sums are the kernels' (TemplateModel::blocked_limbs).
  constexpr int kBlock = TemplateModel::kStateBlock;
  const int dims = model.num_dims();
  const int posture = dims - model.velocity_dims();
  const std::uint16_t* lane =
      model.blocked_features().data() +
      static_cast<std::size_t>(i / kBlock) * static_cast<std::size_t>(dims) * kBlock +
      static_cast<std::size_t>(i % kBlock);
  float phi_blocked[TemplateModel::kMaxLimbModelDims];
  phi = model.in_blocked_order(phi, phi_blocked);
  const auto range_distance = [&](int begin, int end) {
    float sum = 0.0f;
    for (int k = begin; k < end; ++k) {
      const std::uint16_t bits = lane[static_cast<std::size_t>(k) * kBlock];
      const float diff = static_cast<float>(Eigen::numext::bit_cast<Eigen::half>(bits)) - phi[k];
      sum += diff * diff;
    }
    return sum;
  };
  float posture_d2 = 0.0f;
  float limb_excess = 0.0f;  // what the limb bound takes off
  if (limbs_bounded(model, caps)) {
    const std::vector<TemplateModel::DimRange>& limbs = model.blocked_limbs();
    posture_d2 = range_distance(0, limbs.front().begin);
    float farthest = 0.0f, second = 0.0f;
    for (const TemplateModel::DimRange& limb : limbs) {
      const float limb_d2 = range_distance(limb.begin, limb.end);
      posture_d2 += limb_d2;
      second = std::max(second, std::min(farthest, limb_d2));
      farthest = std::max(farthest, limb_d2);
    }
    limb_excess =
        farthest - std::min(farthest, std::max(caps.limb_ratio * second, caps.limb_floor));
  } else {
    posture_d2 = range_distance(0, posture);
  }
  const float velocity_d2 = range_distance(posture, dims);
  const float plain = std::min(posture_d2 + std::min(velocity_d2, caps.velocity), FLT_MAX);
  return {std::min(plain - limb_excess, FLT_MAX), plain};
}

float lost_test_distance(const TemplateModel& model, const FollowParams& params, const float* phi,
                         float best_plain_sq, int state) noexcept {
  DistanceCaps caps = emission_caps(params);
  caps.velocity = std::min(params.velocity_distance_cap,
                           params.lost_velocity_cap_per_dim * static_cast<float>(model.num_dims()));
  if (!(caps.velocity < params.velocity_distance_cap) || state < 0 || state >= model.num_states()) {
    return best_plain_sq;
  }
  return std::min(best_plain_sq, state_emission_distance(model, phi, state, caps).plain);
}

bool limb_out_of_line(const TemplateModel& model, const FollowParams& params, const float* phi,
                      int state) noexcept {
  if (phi == nullptr || state < 0 || state >= model.num_states()) return false;
  const EmissionDistance distance =
      state_emission_distance(model, phi, state, emission_caps(params));
  return distance.bounded < distance.plain;
}

double weigh_and_normalise(const float* predicted, const float* distance_sq, float best_distance_sq,
                           float inv_two_sigma_sq, int num_states, float log_b_pause,
                           bool with_pause, float* out) noexcept {
  const ConstArrayMap pred(predicted, num_states);
  const ConstArrayMap d2(distance_sq, num_states);
  ArrayMap post(out, num_states);

  const float max_template = log_emission(best_distance_sq, inv_two_sigma_sq);
  const float shift = with_pause ? std::max(max_template, log_b_pause) : max_template;
  // One fused, vectorised pass: log-emission, shift, exp, times the prediction.
  float weighted_sum = 0.0f;
#if defined(__x86_64__)
  if (simd_level() == SimdLevel::kAvx2) {
    weighted_sum =
        avx2::weigh_emissions(predicted, distance_sq, inv_two_sigma_sq, shift, num_states, out);
  } else
#endif
  {
    post = pred * ((d2 * -inv_two_sigma_sq).max(kMinLogEmission) - shift).exp();
    weighted_sum = post.sum();
  }
  float pause = with_pause ? predicted[num_states] * std::exp(log_b_pause - shift) : 0.0f;
  double sum = static_cast<double>(weighted_sum) + pause;
  double log_c = static_cast<double>(shift);

  if (!(sum >= kMinNormaliser)) {
    // Slow path, rare: shift by the largest log(predicted * b) instead. Relative to
    // max_template first so that floored log-emissions (-1e30) keep their predicted ratios.
    auto relative = [&](int i) {
      return static_cast<double>(log_emission(distance_sq[i], inv_two_sigma_sq) - max_template) +
             std::log(static_cast<double>(predicted[i]));
    };
    double best = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < num_states; ++i) {
      if (predicted[i] > 0.0f) best = std::max(best, relative(i));
    }
    const bool pause_has_mass = with_pause && predicted[num_states] > 0.0f;
    const double pause_term = pause_has_mass
                                  ? static_cast<double>(log_b_pause - max_template) +
                                        std::log(static_cast<double>(predicted[num_states]))
                                  : -std::numeric_limits<double>::infinity();
    best = std::max(best, pause_term);
    if (!std::isfinite(best)) {
      // No predicted mass anywhere: a broken invariant. Start over from uniform.
      assert(false && "forward variable lost all its mass");
      post.setConstant(1.0f / static_cast<float>(num_states));
      out[num_states] = 0.0f;
      return static_cast<double>(shift);
    }
    sum = 0.0;
    for (int i = 0; i < num_states; ++i) {
      const double term = predicted[i] > 0.0f ? std::exp(relative(i) - best) : 0.0;
      post[i] = static_cast<float>(term);
      sum += term;
    }
    pause = pause_has_mass ? static_cast<float>(std::exp(pause_term - best)) : 0.0f;
    sum += pause;
    log_c = best + static_cast<double>(max_template);
  }

  const float scale = static_cast<float>(1.0 / sum);
  post *= scale;
  out[num_states] = pause * scale;
  return std::log(sum) + log_c;
}

void normalise(float* mass, int count, int uniform_count) noexcept {
  ArrayMap m(mass, count);
  const float sum = m.sum();
  if (sum > 0.0f && std::isfinite(sum)) {
    m *= 1.0f / sum;
    return;
  }
  assert(false && "forward variable lost all its mass");
  m.setZero();
  m.head(uniform_count).setConstant(1.0f / static_cast<float>(uniform_count));
}

void describe_state(const TemplateModel& model, const float* posterior, float total, int state,
                    int window, FollowResult& result, std::span<const int> support) noexcept {
  const int take = model.take_of(state);
  float mass = 0.0f;
  float offset = 0.0f;  // the window's mean frame - state
  if (const CopyPlaces* places = model.copy_places(); places != nullptr) {
    mass = support.empty() ? places->window_mass(posterior, state, window)
                           : places->window_mass(posterior, state, window, support);
  } else {
    const int begin = std::max(model.take_begin(take), state - window);
    const int end = std::min(model.take_end(take), state + window + 1);
    float moment = 0.0f;
    for (int i = begin; i < end; ++i) {
      mass += posterior[i];
      moment += static_cast<float>(i - state) * posterior[i];
    }
    offset = mass > 0.0f ? moment / mass : 0.0f;
  }
  result.state = state;
  result.take = take;
  result.frame_in_take = state - model.take_begin(take);
  result.confidence = total > 0.0f ? std::clamp(mass / total, 0.0f, 1.0f) : 0.0f;
  result.window_mass = result.confidence;
  result.frame_offset = std::isfinite(offset) ? offset : 0.0f;
}

void decide(const TemplateModel& model, const float* posterior, float total, float pause_mass,
            int previous_state, int steps, int window, FollowResult& result) noexcept {
  const int num_states = model.num_states();
  int state = 0;
#if defined(__x86_64__)
  if (simd_level() == SimdLevel::kAvx2) {
    state = avx2::argmax(posterior, num_states);
  } else
#endif
  {
    float best = posterior[0];
    for (int i = 1; i < num_states; ++i) {
      if (posterior[i] > best) {
        best = posterior[i];
        state = i;
      }
    }
  }
  describe_state(model, posterior, total, state, window, result);
  result.in_pause = pause_mass > 0.5f * total;
  result.jumped = model.is_jump(previous_state, state, steps);
}

}  // namespace duet::follow_detail
