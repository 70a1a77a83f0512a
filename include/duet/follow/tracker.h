// The interface every follower implements (the HMM with the jump and the baselines of
// method.md 7), so the evaluation and the live session can swap them.
#pragma once

#include <span>
#include <string_view>

namespace duet {

// What one input frame tells about the dancer's place in the template library.
struct FollowResult {
  int state = -1;           // estimated template state (global index in [0, M)); eq. 8-9
  int take = -1;            // the take that contains state
  int frame_in_take = -1;   // state - first state of that take
  // The probability that state is within 100 ms of the dancer's true place, [0, 1]: the
  // posterior mass within the confidence window around state, mapped through a calibration
  // fitted on `duet eval` performances (confidence_calibration.h; raw where a tracker has none).
  float confidence = 0.0f;
  float window_mass = 0.0f;  // that posterior mass before calibration
  // The posterior's mean frame within that window, minus state: where between frames the dancer
  // is (the partner's playhead aims there). 0 for trackers without a posterior, and in a library
  // of grown copies.
  float frame_offset = 0.0f;
  // The estimate moved by something other than 0..2n frames forward within its take (n = steps),
  // or changed take: the dancer left their figure for another part of the dance. False on the
  // first frame after reset(); for the HMM followers also for the moves JumpGate does not call a
  // jump (jitter back, a catch-up forward within the take, the first placement, a burst).
  bool jumped = false;
  bool lost = false;      // no template frame explains the input (see FollowParams)
  // Lost only because the estimate has held one place longer than a dance holds a pose
  // (FollowParams::held_place_lost_s): a dancer standing still, whom the partner waits with
  // instead of dancing on as through a spell the library does not explain.
  bool held_still = false;
  // Lost (and held_still) because the estimate has not moved on since the follower found a place
  // again after a spell lost by distance (FollowParams::found_still_spell_s): a person who stopped
  // moving after motion no take explains, whom a stance matches. The input's evidence did not
  // call it lost, so the rig's offset is not searched or let go for it (FollowSession).
  bool still_since_lost = false;
  bool in_pause = false;  // the pause state holds most of the posterior mass
  bool missing = false;   // the input held NaN/inf: transition only, no emission
  // Some of the input's dimensions were NaN, the rest evidence (a controller out of the
  // headset's view): the unobserved ones were carried along the dance (the hmm trackers; the
  // others take such a frame as missing).
  bool partly_observed = false;
  // An outlier frame (FollowParams::gate_outliers): its evidence would have handed the pause
  // state the majority right after a frame that was followed, so it was set aside like a dropped
  // frame's (the estimate moved on along the band).
  bool outlier = false;
  // At the estimated state one limb is far out of line with the others, so the emission bounded
  // its share (FollowParams::limb_outlier_ratio): a held or gesturing limb the library does not
  // hold. Such a frame does not teach the explained residual (explained_residual.h).
  bool limb_out_of_line = false;
  int steps = 0;          // template-rate transitions applied for this frame
  // log p(phi_t | phi_1..t-1), up to the Gaussian's constant normaliser; 0 for missing frames.
  // Trackers that are not probabilistic report the negative best distance / (2 sigma^2).
  double log_likelihood = 0.0;
  // min_i ||phi - phi_i||^2 / D over all states (online DTW: over its window), the HMM's with
  // the velocity cap (FollowParams::velocity_distance_cap) but every limb in full: how far the
  // input is from the library, whatever the emission's limb bound weighs; -1 if missing.
  float best_distance_per_dim = 0.0f;
  // The input sensor's white-noise variance per posture dimension as the tracker estimates it
  // online (sensor_noise.h); 0 for trackers that do not.
  float sensor_noise_per_dim = 0.0f;
  // The dancer's tempo as the tracker sees it (template frames per template frame of input time,
  // 1 = the template's tempo); 1 for trackers that do not estimate one.
  float tempo = 1.0f;
  // Set by FollowSession (0 from a tracker alone): the user's rig's posture offset it removes
  // (RMS per posture dimension, standardised units) and the confident seconds it has been learnt
  // for, and the confidence as the tracker gave it, before the session's account of an offset
  // still young (young_offset_confidence.h).
  float rig_offset = 0.0f;
  float rig_offset_learnt_s = 0.0f;
  float tracker_confidence = 0.0f;
};

// A per-frame follower. step() is the live path: it allocates nothing, throws nothing and does no
// I/O; all buffers are sized when the tracker is created.
class Tracker {
 public:
  virtual ~Tracker() = default;

  // Forget the past: the next step starts from the initial distribution.
  virtual void reset() noexcept = 0;

  // features: one input frame, D floats, computed like the template's (method.md 3). A frame
  //   with NaN or inf is treated as missing. A size other than D is a broken contract (asserts;
  //   treated as missing in release builds).
  // dt_s: time since the previous input frame in seconds (the input rate may differ from the
  //   template's, frames may be late); <= 0 or non-finite counts as one template frame.
  virtual FollowResult step(std::span<const float> features, double dt_s) noexcept = 0;

  virtual std::string_view name() const noexcept = 0;

 protected:
  // Copy and move only through concrete trackers (no slicing through a Tracker&).
  Tracker() = default;
  Tracker(const Tracker&) = default;
  Tracker& operator=(const Tracker&) = default;
  Tracker(Tracker&&) = default;
  Tracker& operator=(Tracker&&) = default;
};

}  // namespace duet
