// Pieces shared by the HMM follower and its baselines: emissions, normalisation, decisions.
// All of them are on the per-frame path: no allocation, no exceptions.
#pragma once

#include <cfloat>
#include <span>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include "duet/follow/follow_params.h"
#include "duet/follow/template_model.h"
#include "duet/follow/tracker.h"

namespace duet::follow_detail {

// Floor for log-emissions: keeps -d^2 / (2 sigma^2) finite when d^2 overflows float, so that
// (log_b - max) never becomes -inf - -inf = NaN.
inline constexpr float kMinLogEmission = -1e30f;

// Flushes denormal floats to zero (FTZ and DAZ) for the lifetime of the object and restores the
// caller's floating-point mode afterwards. The emissions of far states are exp(-large), whose
// denormal results cost ~100 cycles each: this halves the step at 27k states. Mass below
// 1.2e-38 becomes exactly 0, which the pause state's resume path makes harmless.
class ScopedFlushDenormals {
 public:
#if defined(__SSE2__)
  ScopedFlushDenormals() noexcept : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | kFtzDaz); }
  ~ScopedFlushDenormals() { _mm_setcsr(saved_); }

 private:
  static constexpr unsigned kFtzDaz = 0x8040;  // MXCSR flush-to-zero | denormals-are-zero
  unsigned saved_;
#endif
 public:
  ScopedFlushDenormals(const ScopedFlushDenormals&) = delete;
  ScopedFlushDenormals& operator=(const ScopedFlushDenormals&) = delete;
};

bool all_finite(std::span<const float> values) noexcept;

// n = clamp(round(dt_s * template_fps), 1, max_steps); dt_s <= 0 or non-finite gives 1.
int steps_for(double dt_s, double template_fps, int max_steps) noexcept;

// out[i - begin] = ||phi - phi_i||^2 for template rows i in [begin, end), saturated at FLT_MAX.
// Returns the minimum. phi has model.num_dims() finite values.
float squared_distances(const FeatureView& features, const float* phi, int begin, int end,
                        float* out) noexcept;

// The robust emission's bounds on parts of the squared distance (eq. 7 with
// FollowParams::velocity_distance_cap and limb_outlier_ratio): the velocity dimensions' share
// counts at most `velocity`; the limb (TemplateModel::limbs) that is farthest counts at most
// limb_ratio times the second farthest, and never less than limb_floor. FLT_MAX or more: no
// bound.
struct DistanceCaps {
  float velocity = FLT_MAX;
  float limb_ratio = FLT_MAX;
  float limb_floor = 0.0f;
};
DistanceCaps emission_caps(const FollowParams& params) noexcept;
// Whether the farthest limb is bounded: a ratio is set and the model has two limbs or more.
inline bool limbs_bounded(const TemplateModel& model, DistanceCaps caps) noexcept {
  return caps.limb_ratio < FLT_MAX && model.limbs().size() >= 2;
}

// One state's squared distance with the caps (`bounded`, the emission's) and with only the
// velocity cap (`plain`). The limb bound decides between places; whether a place explains the
// input (FollowResult::best_distance_per_dim: the lost test, the residual it scales with, the
// rig offset's learning) counts every limb: a wave is one arm out of line with a standing body.
struct EmissionDistance {
  float bounded = FLT_MAX;
  float plain = FLT_MAX;
};

// out[i] = the bounded distance of every template state i (squared_distances when nothing is
// capped). Returns the minimum of each kind over the states.
EmissionDistance emission_distances(const TemplateModel& model, const float* phi, DistanceCaps caps,
                                    float* out) noexcept;

// The same for one template state i. Read from the blocked features, which the full step keeps
// resident anyway: the row-major ones may be a memory-mapped cache's
// (TemplateModel::build_shared), whose pages a beam's scattered jump candidates would otherwise
// bring in one by one (at 1M states, 150 MB in the first seconds). O(D).
EmissionDistance state_emission_distance(const TemplateModel& model, const float* phi, int i,
                                         DistanceCaps caps) noexcept;

// The squared distance of the lost test (FollowParams::lost_velocity_cap_per_dim): the best plain
// emission distance, or the plain one at the estimated state with the velocity part capped
// lower, whichever is smaller. `state` < 0: the best plain distance.
float lost_test_distance(const TemplateModel& model, const FollowParams& params, const float* phi,
                         float best_plain_sq, int state) noexcept;

// Whether the limb bound takes anything off the emission distance at `state` (FollowResult::
// limb_out_of_line). False without features (phi null) or a state.
bool limb_out_of_line(const TemplateModel& model, const FollowParams& params, const float* phi,
                      int state) noexcept;

// log b = max(-d^2 * inv_two_sigma_sq, kMinLogEmission) (eq. 7, without its constant).
inline float log_emission(float distance_sq, float inv_two_sigma_sq) noexcept {
  const float log_b = -distance_sq * inv_two_sigma_sq;
  return log_b > kMinLogEmission ? log_b : kMinLogEmission;
}

// The outer factor of eq. 10/11 and the normalisation:
//   out_i = predicted_i * b_i / c,   c = sum_i predicted_i * b_i,
// over num_states template states plus, if with_pause, the pause state at index num_states
// (predicted and out have num_states + 1 entries; without the pause out[num_states] = 0).
// distance_sq holds d_i^2 and best_distance_sq their minimum. The exponentials are taken after
// subtracting the largest log-emission, so the best state's factor is exactly 1. If c still
// underflows (all the predicted mass sits on states with tiny emissions), the frame is redone
// with the exact shift max_i(log b_i + log predicted_i), which makes the largest term 1.
// Returns log c in absolute terms: log p(phi_t | phi_1..t-1) up to the Gaussian's constant.
double weigh_and_normalise(const float* predicted, const float* distance_sq, float best_distance_sq,
                           float inv_two_sigma_sq, int num_states, float log_b_pause,
                           bool with_pause, float* out) noexcept;

// Rescales mass[0..count) to sum to 1; a zero or non-finite sum (a broken invariant) becomes
// uniform over the first uniform_count entries.
void normalise(float* mass, int count, int uniform_count) noexcept;

// Fills state (= `state`), take, frame_in_take, confidence (mass within +/- window frames in
// the same take, divided by total) and frame_offset (that mass's mean frame - state).
// In a library grown with copies (TemplateModel::copy_places) the window is taken in the captured
// takes, over every copy (frame_offset 0 there); `support`, when not empty, lists the only states
// that can hold mass (a beam), which is then all that is read.
void describe_state(const TemplateModel& model, const float* posterior, float total, int state,
                    int window, FollowResult& result, std::span<const int> support = {}) noexcept;

// Fills state (argmax of posterior over the M template states, eq. 8-9), take, frame_in_take,
// confidence (mass within +/- window frames in the same take, divided by total), in_pause
// (pause_mass > 0.5) and jumped (relative to previous_state, -1 for none).
void decide(const TemplateModel& model, const float* posterior, float total, float pause_mass,
            int previous_state, int steps, int window, FollowResult& result) noexcept;

}  // namespace duet::follow_detail
