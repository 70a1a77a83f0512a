// Partner metrics (method.md 7, of the synthesis of method.md 5): the synthesized partner against
// the true response, i.e. what the partner would have been had the follower known the true
// template frame of every input frame. Exact definitions in docs/evaluation.md, "Partner metrics".
//
//   joint error   mean over joints of |synthesized - true response| world positions, where the
//                 true response is the response clip sampled at the TRUE template frame and placed
//                 by the same alignment (5.1) relative to the user's current root: compared in the
//                 user's frame;
//   hand error    at frames whose true template frame has a hand contact (5.2), per contacting
//                 pair: | output wrist-to-user-wrist distance - captured wrist-to-wrist distance |
//                 (the user's real wrist, before the sensor's noise; and the sensed one);
//   foot slip     frames in which a toe near its ground height (FootSlipThresholds, the
//                 PartnerModel's ground heights) moves horizontally faster than a threshold
//                 (5.3); also for the captured response over its own takes;
//   jump speed    the largest local joint angular speed in the window after each true jump,
//                 against the captured response's 99th percentile (5.3 blending);
//   jerk          mean over joints of |third derivative| of the world positions, against the
//                 true response's over the same performance;
//   steadiness    the 99th percentile of the per-frame largest joint angular speed, against the
//                 captured response's over its takes (issue 11: the user's sensor noise must not
//                 reach the partner's joints);
//   after a jump  the time until the hands are rejoined and the spacing is the captured one
//                 again, the spacing error a fixed time after the jump, and the speed of planted
//                 feet in the window after the jump;
//   crowding      frames where the partner's pelvis comes within crowd_distance_m of the user's
//                 while the captured partner's keeps crowd_distance_m + crowd_margin_m away (the
//                 partner walks into the user), and the closest it comes there.
//
// Offline code: allocates freely (it is not on the live path; the synthesis it measures is).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "duet/eval/performance.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"
#include "duet/partner/partner_synthesis.h"

namespace duet {

// What counts as a slipping foot. Fixed here rather than taken from FootLockParams, so that
// retuning the foot lock cannot move the yardstick it is measured with.
struct FootSlipThresholds {
  double height_margin_m = 0.03;  // toe above its ground height
  double speed_mps = 0.2;         // horizontal toe speed above which it slips
};

struct PartnerMetricsOptions {
  FootSlipThresholds slip;
  double post_jump_window_s = 0.5;  // frames with t_jump <= t < t_jump + window follow a jump
  double reference_percentile = 0.99;
  // After a jump (issue 11's targets): the partner has rejoined when every hand pair the true
  // response holds is within rejoin_tolerance_m of the captured wrist distance and the spacing
  // (horizontal pelvis-to-pelvis distance) within rejoin_tolerance_m of the true response's, and
  // stays so for rejoin_hold_s; searched up to rejoin_search_s after the jump (not found: the
  // jump counts as not rejoined). The spacing error is also read rejoin_deadline_s after it.
  double rejoin_tolerance_m = 0.05;
  double rejoin_hold_s = 0.1;
  double rejoin_search_s = 1.0;
  double rejoin_deadline_s = 0.3;
  // A planted foot: the true response's toe is planted at the true frame (within
  // slip.height_margin_m of its ground and slower than planted_speed_mps) and the partner's toe
  // is near the ground; it slides when the partner's toe moves faster than slide_limit_mps.
  double planted_speed_mps = 0.3;
  double slide_limit_mps = 0.3;
  // Too close: the partner's pelvis within crowd_distance_m of the user's (horizontally) at a
  // frame where the true response's is at least crowd_distance_m + crowd_margin_m from it. Salsa
  // partners come that close only where the capture does (a blend that carried the partner
  // through the user came within 0.12 m: docs/evaluation.md, "Round the user").
  double crowd_distance_m = 0.3;
  double crowd_margin_m = 0.1;
};

// ---------------------------------------------------------------------------------------------
// Per-frame geometry

// Mean over joints of the distance between two sets of world positions (same size, > 0), metres.
double mean_joint_distance_m(std::span<const Vec3> a, std::span<const Vec3> b);

// Angle of the rotation from `previous` to `current` divided by dt (radians per second); 0 when
// dt <= 0 or not finite. The shorter way round (q and -q are the same rotation).
double angular_speed_rad_s(const Quat& previous, const Quat& current, double dt_s);

// Largest angular speed over the skeleton's animated joints (End Sites are never rotated).
double max_joint_angular_speed_rad_s(const Skeleton& skeleton, std::span<const Quat> previous_ls,
                                     std::span<const Quat> current_ls, double dt_s);

// A toe near the ground: both positions within the margin of its ground height.
bool foot_near_ground(const Vec3& previous_ws, const Vec3& current_ws, double ground_height_m,
                      const FootSlipThresholds& thresholds);
// Horizontal (x, z) speed between two positions; 0 when dt <= 0 or not finite.
double horizontal_speed_mps(const Vec3& previous_ws, const Vec3& current_ws, double dt_s);
// A toe near the ground that slides: foot_near_ground and the horizontal speed above the
// threshold.
bool foot_slips(const Vec3& previous_ws, const Vec3& current_ws, double ground_height_m,
                double dt_s, const FootSlipThresholds& thresholds);

// Jerk of a moving skeleton by backward differences of its world positions: velocity,
// acceleration and jerk each over the step's dt (exact for a cubic path at a steady rate). Sized
// once for a joint count; add() allocates nothing.
class JerkMeter {
 public:
  explicit JerkMeter(std::size_t joints = 0);
  // Forget the past (e.g. where the motion is cut): the next three frames give no jerk.
  void reset() noexcept { known_ = 0; }
  // Adds a frame dt_s after the previous one (ignored for the first frame after a reset) and
  // returns the mean over joints of |jerk| (m/s^3) at it, or -1 while fewer than four frames are
  // known or when dt_s is not positive and finite (which also resets).
  double add(std::span<const Vec3> positions_ws, double dt_s) noexcept;

 private:
  std::vector<Vec3> position_, velocity_, acceleration_;
  int known_ = 0;  // frames since the reset, up to 4
};

// The captured duet of one take, sampled at a real template frame (Clip::sample: translations
// lerped, rotations slerped). Sized once; compute() reuses its buffers.
class CapturedDuetSampler {
 public:
  // template_clip / response_clip: the take's two clips (same frame count and rate); model: the
  // PartnerModel of that take (alignment and contacts). All must outlive the sampler.
  CapturedDuetSampler(const Clip& template_clip, const JointRoles& template_roles,
                      const Clip& response_clip, const PartnerModel& model);

  // Samples both dancers at `template_frame` (clamped to the take) in the capture's world frame,
  // and places the response like the synthesis's alignment does: root = heading frame of the
  // user's root times the placement (interpolated between the two nearest frames).
  void compute(double template_frame, const Vec3& user_root_position_ws,
               const Quat& user_root_rotation_ws);
  // Same, placed in a given heading frame of the user: the body heading frame
  // (body_heading_frame) the synthesis places the partner in, so a user on any rig is scored in
  // the frame the partner was placed in. spacing_scale: the captured spacing fitted to the user's
  // body as the synthesis fits it (PartnerModel::spacing_scale of the user's height), so a
  // taller user's partner is scored against the place it is meant to stand at.
  void compute(double template_frame, const Transform& user_heading, double spacing_scale = 1.0);

  // The true response, placed relative to the user (world positions and local rotations).
  std::span<const Vec3> placed_positions_ws() const { return placed_positions_; }
  std::span<const Quat> placed_rotations_ls() const { return placed_pose_.rotations_ls; }
  // Captured distance between the template's and the response's wrists of a hand pair (capture
  // frame, metres).
  double captured_wrist_distance_m(int pair) const;
  // Contacts at the nearest integer frame (bit = hand pair).
  std::uint8_t contact_mask() const { return mask_; }

 private:
  const Clip* template_clip_;
  JointRoles template_roles_;
  const Clip* response_clip_;
  const PartnerModel* model_;
  Pose template_pose_, response_pose_, placed_pose_;
  std::vector<Vec3> template_positions_, response_positions_, placed_positions_;
  std::vector<Quat> rotations_scratch_;
  std::uint8_t mask_ = 0;
};

// ---------------------------------------------------------------------------------------------
// One synthesized partner over one performance

// What the metrics keep of one frame of the synthesis.
struct PartnerFrameRecord {
  double joint_error_m = 0.0;
  // Hand error per pair, only for pairs in contact at the true template frame: against the
  // user's real wrist (Performance::true_wrists_ws, the sensed one when the sensor adds no
  // noise), and against the wrist the sensor reports. Under a noisy sensor a partner hand that
  // stays steady at the real hand is off the sensed one by the noise; one that chases the sensed
  // hand shakes.
  std::array<double, kHandPairCount> hand_error_m{};
  std::array<double, kHandPairCount> sensed_hand_error_m{};
  std::uint8_t hand_pairs = 0;  // bit p: hand_error_m[p] is set
  bool slip = false;            // a foot slipped since the previous frame (false on frame 0)
  // Horizontal speeds of the toes that stayed near the ground since the previous frame, summed,
  // and how many (0-2): the mean skating speed, which also sees sliding below the threshold.
  double ground_speed_sum_mps = 0.0;
  int ground_feet = 0;
  double max_angular_speed_rad_s = 0.0;  // since the previous frame (0 on frame 0)
  // The same for the true response (0 on frame 0 and at a true jump, where it is cut).
  double true_max_angular_speed_rad_s = 0.0;
  // Mean joint jerk (m/s^3) of the output and of the true response (JerkMeter; -1 where it is
  // not known: the first frames, and the true response's first frames after a cut).
  double jerk_mps3 = -1.0;
  double true_jerk_mps3 = -1.0;
  double step_us = 0.0;  // wall-clock time of the loop step that made it
  // Every hand pair the true response holds at this frame is within rejoin_tolerance_m of the
  // captured wrist distance (true when it holds none).
  bool hands_joined = true;
  // | partner-to-user - true-response-to-user horizontal pelvis distance |, metres.
  double spacing_error_m = 0.0;
  // Largest horizontal speed of a partner toe on a planted foot since the previous frame (see
  // PartnerMetricsOptions), m/s; -1 when no foot is planted.
  double planted_slide_mps = -1.0;
  // Horizontal pelvis-to-user-root distance of the partner and of the true response, metres.
  double user_distance_m = 0.0;
  double true_user_distance_m = 0.0;
};

// The captured response of the takes a performance was made from, at the take's own rate: the
// references for foot slip and angular speed.
struct CapturedReference {
  long long slip_frames = 0;                 // frames (from the second) in which a foot slipped
  long long frames = 0;                      // frames from the second
  double ground_speed_sum_mps = 0.0;         // toes near the ground: speeds summed ...
  long long ground_feet = 0;                 // ... and counted
  std::vector<double> angular_speeds_rad_s;  // every animated joint, every frame from the second
  // Non-overlapping windows of post_jump_window_s over the take: how often the captured motion
  // itself exceeds its percentile inside such a window (context for the jump metric).
  long long windows = 0;
  std::vector<double> window_max_rad_s;
  // The largest animated joint's angular speed of every frame from the second.
  std::vector<double> frame_max_rad_s;
};
// Adds one take's response clip (roles: its joint roles; ground: the PartnerModel's heights).
void add_captured_reference(const Clip& response, const JointRoles& roles,
                            const std::array<double, 2>& ground_heights,
                            const PartnerMetricsOptions& options, CapturedReference& reference);

// The summary of one or more synthesized performances (one configuration of the corrections).
struct PartnerMetrics {
  long long frames = 0;
  double mean_joint_error_cm = 0.0;
  long long hand_samples = 0;         // (frame, contacting pair) samples
  double median_hand_error_cm = 0.0;  // against the real wrists (PartnerFrameRecord)
  double mean_hand_error_cm = 0.0;
  double median_sensed_hand_error_cm = 0.0;  // against the sensed wrists
  double slip_rate = 0.0;                    // slipping frames / frames from the second
  double ground_speed_cm_s = 0.0;            // mean horizontal speed of toes near the ground
  long long jumps = 0;  // true jumps whose window holds at least one frame after the first
  double max_jump_speed_deg_s = 0.0;     // largest over every jump window
  double median_jump_speed_deg_s = 0.0;  // median over jumps of each window's largest
  long long jumps_over_reference = 0;    // windows whose largest exceeds the reference
  // Windows whose largest exceeds both the reference and the true response's own largest in
  // that window (the dance itself may spin faster than the percentile right after a jump).
  long long jumps_over_truth = 0;
  double median_true_jump_speed_deg_s = 0.0;  // median over jumps of the true response's largest
  // Mean over frames of the mean joint jerk, m/s^3: the output's and the true response's (each
  // over the frames where it is known).
  double mean_jerk_mps3 = 0.0;
  double true_mean_jerk_mps3 = 0.0;
  double mean_step_us = 0.0;
  // The captured response's own numbers over the same takes.
  double captured_slip_rate = 0.0;
  double captured_ground_speed_cm_s = 0.0;
  double reference_speed_deg_s = 0.0;            // its reference_percentile angular speed
  double captured_windows_over_reference = 0.0;  // fraction of its windows over that
  // The like-for-like reference: the reference_percentile of the captured response's largest
  // speed per post_jump_window_s window (the statistic a jump window is measured with), and the
  // jumps whose window exceeds it.
  double window_reference_speed_deg_s = 0.0;
  long long jumps_over_window_reference = 0;
  // Of those, the jumps whose window also exceeds the true response's largest in that window:
  // spikes the dance itself does not have there (a captured take may itself spin a joint faster
  // than the reference, e.g. 61_07's left hand at 4100 deg/s in its first frames).
  long long jumps_over_window_reference_and_truth = 0;

  // Steadiness: the reference_percentile of the per-frame largest joint angular speed, of the
  // output (frames from the second) and of the captured response over the same takes.
  double frame_speed_deg_s = 0.0;
  double captured_frame_speed_deg_s = 0.0;
  // The same percentile for the true response as the performance shows it (the captured partner
  // at the true frames, at the performance's timing; frames of a true jump left out, where the
  // true response is cut): a performance danced 1.4x faster than the capture asks a partner
  // 1.4x faster than the captured one. 0 without such frames.
  double true_frame_speed_deg_s = 0.0;
  // After the jumps (the `jumps` above): rejoin time, median and largest over jumps (seconds;
  // infinity when some jump did not rejoin within rejoin_search_s), and how many rejoined within
  // rejoin_deadline_s.
  double median_rejoin_s = 0.0;
  double max_rejoin_s = 0.0;
  long long jumps_rejoined_in_time = 0;
  // Spacing error rejoin_deadline_s after each jump, cm: median and largest over jumps.
  double median_spacing_error_cm = 0.0;
  double max_spacing_error_cm = 0.0;
  // Planted feet in the window after each jump: the largest slide speed over jumps (m/s) and the
  // jumps where it exceeds slide_limit_mps; and over every frame of the performance.
  double max_jump_slide_mps = 0.0;
  long long jumps_sliding = 0;
  double max_slide_mps = 0.0;
  long long sliding_frames = 0;  // frames with a planted foot above slide_limit_mps
  // Crowding (PartnerMetricsOptions::crowd_distance_m): frames too close, the jumps with such a
  // frame in their window, and the partner's smallest distance to the user (cm) over the frames
  // where the true response keeps crowd_distance_m + crowd_margin_m away (-1: no such frame).
  long long crowded_frames = 0;
  long long jumps_crowded = 0;
  double closest_cm = -1.0;
};

// Pools the records of performances (frames and jumps weigh equally across performances) and
// the captured references of their takes.
class PartnerMetricsAccumulator {
 public:
  explicit PartnerMetricsAccumulator(PartnerMetricsOptions options = {}) : options_(options) {}

  // records: one per frame of `performance` (times and truth come from it).
  void add(const Performance& performance, std::span<const PartnerFrameRecord> records);
  void add_reference(const CapturedReference& reference);
  void merge(const PartnerMetricsAccumulator& other);

  PartnerMetrics summary() const;
  const PartnerMetricsOptions& options() const { return options_; }

 private:
  PartnerMetricsOptions options_;
  long long frames_ = 0, slip_frames_ = 0, slip_pairs_ = 0, ground_feet_ = 0;
  double ground_speed_sum_mps_ = 0.0;
  double joint_error_sum_m_ = 0.0, step_us_sum_ = 0.0;
  double jerk_sum_ = 0.0, true_jerk_sum_ = 0.0;
  long long jerk_frames_ = 0, true_jerk_frames_ = 0;
  std::vector<double> hand_errors_m_, sensed_hand_errors_m_;
  std::vector<double> jump_max_rad_s_;  // one per jump window
  std::vector<double> jump_true_max_rad_s_;
  std::vector<double> frame_max_rad_s_;       // output, frames from the second
  std::vector<double> true_frame_max_rad_s_;  // the true response, frames that are no true jump
  std::vector<double> jump_rejoin_s_;         // per jump window; infinity: not rejoined
  std::vector<double> jump_spacing_m_;        // per jump, rejoin_deadline_s after it
  std::vector<double> jump_slide_mps_;        // per jump, largest planted slide in the window
  double max_slide_mps_ = 0.0;
  long long sliding_frames_ = 0;
  long long crowded_frames_ = 0, jumps_crowded_ = 0;
  double closest_m_ = std::numeric_limits<double>::infinity();  // see PartnerMetrics::closest_cm
  CapturedReference reference_;
};

// The value at quantile q in [0, 1] of `values` (nearest rank on the sorted copy; 0 when empty).
double quantile(std::vector<double> values, double q);

}  // namespace duet
