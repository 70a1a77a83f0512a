// Synthetic performances with ground truth (method.md 7).
//
// A performance is what a user would send to the follower: one pose per input frame with the
// sensor's timestamp. It is synthesised from a real take of the library, so the true template
// position of every frame is known. Generators:
//   play()       the whole take at a steady or smoothly drifting tempo;
//   improvise()  the take (or several takes) cut into segments of a few seconds, replayed in
//                another order with repeats and skips, optionally with a short pause before each
//                jump; every segment is moved and turned about the vertical axis so the root path
//                stays continuous (the user does not teleport);
// and perturbations of a finished performance: sensor noise, dropped and late frames, a
// different body size, a different place and facing in the room. A lower sensor rate is a
// parameter of the generators (the take is sampled at that rate). make_performance() composes
// all of them from a PerformanceRecipe.
//
// Every function is pure: same inputs and seed, same performance. Offline code: allocates,
// never on the per-frame path.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/math/types.h"
#include "duet/motion/arms_forward.h"
#include "duet/motion/clip.h"
#include "duet/motion/head_hands.h"
#include "duet/motion/skeleton_map.h"

namespace duet {

// The truth about one input frame.
struct TruthFrame {
  int take = -1;                // library index of the take the user dances (SourceTake::take)
  double template_frame = 0.0;  // position in that take's template, in template frames (real)
  bool in_pause = false;        // the user holds still before a jump; excluded from accuracy
  bool jump = false;  // the first frame after a jump: the user moved elsewhere in the dance
};

struct Performance {
  // The user's poses, one frame per input frame. motion.frame_rate() is the nominal sensor rate;
  // the real timing is times_s (frames may be missing or late).
  Clip motion;
  JointRoles roles;               // joint roles of motion's skeleton
  std::vector<double> times_s;    // sensor timestamp of each frame, strictly increasing, seconds
  std::vector<TruthFrame> truth;  // one per frame
  double template_rate_hz = 0.0;  // rate of the template frames that truth refers to
  // Where the user's wrists really are (world, Side order), one per frame: recorded before the
  // sensor's noise is added, so the partner's hands can be scored against the real hands as
  // well as against the sensed ones. Empty when the sensor adds no noise (the sensed wrists are
  // the real ones).
  std::vector<std::array<Vec3, 2>> true_wrists_ws;
  // The real body's heading frame (body_heading_frame), one per frame, for a performance reduced
  // to three points (with_head_hands), whose roles name no hips to take it from, or whose sensor
  // stalls or pops (FrameLossOptions::freeze_every_s, SensorNoiseOptions::glitch_every_s: the
  // sensed pose is not where the dancer is); else empty. Recorded before the sensor's noise, as
  // true_wrists_ws.
  std::vector<Transform> true_headings_ws;
  // The head height standing the follower is told (SourceSkeleton::head_height_m), metres; 0:
  // none.
  double told_head_height_m = 0.0;
  // The body calibration the follower is told (SourceSkeleton::arms_forward); nullopt: none.
  std::optional<ArmsForward> told_arms_forward = std::nullopt;

  int frame_count() const { return motion.frame_count(); }
};

// A take to perform from. The clip must outlive the generator call (the result copies poses).
struct SourceTake {
  int take = 0;                // library index, reported in TruthFrame::take
  const Clip* clip = nullptr;  // the take's template clip (the user's role), metres
  JointRoles roles;            // joint roles of clip's skeleton
};

// How fast the user dances: template seconds per performance second (1.4 = 40% faster).
struct TempoOptions {
  double factor = 1.0;  // steady tempo
  // Drifting tempo: when drift_high > drift_low the factor moves smoothly between the two,
  // factor(t) = mid + amp * sin(2 pi t / drift_period_s + phase), phase from the seed; `factor`
  // is then ignored.
  double drift_low = 1.0;
  double drift_high = 1.0;
  double drift_period_s = 12.0;

  bool drifting() const { return drift_high > drift_low; }
};

struct PlayOptions {
  TempoOptions tempo;
  double rate_hz = 0.0;  // sensor rate; 0 = the take's rate
  std::uint64_t seed = 1;
};

// The whole take (first to last frame) at the given tempo and sensor rate. No pauses, no jumps.
// source.clip must have at least 2 frames.
Performance play(const SourceTake& source, const PlayOptions& options);

struct ImproviseOptions {
  TempoOptions tempo;
  double rate_hz = 0.0;     // sensor rate; 0 = the takes' rate
  double duration_s = 0.0;  // length of the performance; 0 = the first source's duration
  // Every source is cut into consecutive segments of [segment_min_s, segment_max_s] template
  // seconds. After a segment the dancer goes on into the next one with continue_prob, otherwise
  // jumps to the start of a random segment of any source (a repeat, a skip ahead or back).
  double segment_min_s = 2.0;
  double segment_max_s = 5.0;
  double continue_prob = 0.2;
  // Before a jump, with pause_prob, the dancer holds the last pose for
  // [pause_min_s, pause_max_s] seconds with a tiny sway (root sway_m, spine sway_deg).
  double pause_prob = 0.0;
  double pause_min_s = 0.3;
  double pause_max_s = 0.8;
  double sway_m = 0.005;
  double sway_deg = 1.0;
  std::uint64_t seed = 1;
};

// Segments of the sources replayed in another order. The sources must share one skeleton layout
// and frame rate, and every clip must have at least 2 frames (else an error). The performance
// uses sources[0]'s skeleton and roles.
Result<Performance> improvise(std::span<const SourceTake> sources, const ImproviseOptions& options);

// A recording of one take danced again (a real capture of the same dance, e.g. take 01 on the
// CMU ASF rig): frame i, at the recording's own rate, is moment i / rate of the take, so its truth
// is template frame i * template_rate_hz / rate. `clip` must be in metres and Y up (as
// load_motion gives it) and `roles` name its joints. Frames past the take's last frame are cut
// off. Error when the clip has fewer than 2 frames, no positive frame rate, or `take_frames` < 2.
Result<Performance> recorded_performance(Clip clip, const JointRoles& roles, int take,
                                         int take_frames, double template_rate_hz);

// Per-frame sensor noise: every joint's local rotation is multiplied by a random rotation whose
// rotation vector has independent normal components (RMS angle rotation_deg), and the root's
// position channels get independent normal noise (per-axis standard deviation position_m; other
// joints' position channels hold bone lengths, which a sensor does not shake).
//
// An inertial suit (Perception Neuron, Xsens, Rokoko) also errs slowly: its calibration leaves
// every joint's rotation off by a constant (bias_deg, RMS angle, drawn once per joint), and its
// sensors drift (drift_deg, RMS angle of a random rotation per joint that wanders with time
// constant drift_time_s: an Ornstein-Uhlenbeck process per axis, in the performance's time).
// Both come after the joint's rotation and before the white noise, from their own random stream.
//
// An optical system loses an arm's markers whenever the partner's body hides them: spans of
// [occlusion_min_s, occlusion_max_s] seconds, one every occlusion_every_s on average (exponential
// waits, never the first frame), in which one arm drawn at random is held where it was last seen
// (its shoulder's, elbow's and wrist's local rotations frozen while the body moves on, as a live
// solver holds a segment it cannot see). The white noise goes on on top; its own random stream.
//
// Any tracker also pops now and then: a joint grossly wrong for a frame or a few (an optical
// marker swapped with a neighbour, a depth camera's limb flipped, an inertial sensor's magnetic
// disturbance): spans of [glitch_min_s, glitch_max_s] seconds, one every glitch_every_s on
// average, in which one joint of the trunk, arms or legs drawn at random is turned by one random
// rotation of glitch_min_deg to glitch_max_deg, about a random axis. Before the white noise; its
// own random stream.
struct SensorNoiseOptions {
  double rotation_deg = 0.0;
  double position_m = 0.0;
  std::uint64_t seed = 1;
  double bias_deg = 0.0;
  double drift_deg = 0.0;
  double drift_time_s = 10.0;
  double occlusion_every_s = 0.0;  // 0: no occlusions
  double occlusion_min_s = 0.3;
  double occlusion_max_s = 1.5;
  double glitch_every_s = 0.0;  // 0: no glitches
  double glitch_min_s = 0.01;   // a frame at 30-120 Hz
  double glitch_max_s = 0.05;   // three frames at 60 Hz
  double glitch_min_deg = 30.0;
  double glitch_max_deg = 90.0;

  bool active() const {
    return rotation_deg > 0.0 || position_m > 0.0 || bias_deg > 0.0 || drift_deg > 0.0 ||
           occlusion_every_s > 0.0 || glitch_every_s > 0.0;
  }
};
Performance with_sensor_noise(Performance performance, const SensorNoiseOptions& options);
// Records the wrists' world positions of the performance as it is now in true_wrists_ws (left
// empty when the roles name no wrists): make_performance calls it before any noise is added.
void record_true_wrists(Performance& performance);
// Records the body's heading frame of every frame in true_headings_ws (empty when the roles name
// no hips): make_performance calls it before reducing a performance to three points.
void record_true_headings(Performance& performance);

// A network or sensor that drops and delays frames. Frames are dropped in bursts of 1..3 (about
// drop_fraction of all frames; the first frame is kept); late_fraction of the kept frames carry a
// timestamp up to late_max_frames sensor periods late; every timestamp gets uniform jitter in
// [0, jitter_s]. Timestamps stay strictly increasing. A jump flag on a dropped frame moves to the
// next kept frame. repeat_fraction of the kept frames (never the first) repeat the previous kept
// frame's pose, as a sensor that sends a stale sample again does; their truth is the repeated
// pose's (a jump flag moves on to the next frame). Tracking losses (an occluded suit, a controller
// out of the headset's view) drop every frame of spans of [gap_min_s, gap_max_s] seconds, one
// every gap_every_s on average (exponential waits between them; never the first frame). Stalls
// (a driver or a stream that stops updating, a headset that lost tracking and holds its last
// pose) deliver every frame of spans of [freeze_min_s, freeze_max_s] seconds, one every
// freeze_every_s on average, as the pose of the frame before the span, bit for bit; the dancer
// dances on, so their truth is the dancer's own frame.
struct FrameLossOptions {
  double drop_fraction = 0.0;
  double late_fraction = 0.0;
  double late_max_frames = 1.5;
  double jitter_s = 0.0;
  std::uint64_t seed = 1;
  double repeat_fraction = 0.0;
  double gap_every_s = 0.0;  // 0: no tracking losses
  double gap_min_s = 0.3;
  double gap_max_s = 1.0;
  double freeze_every_s = 0.0;  // 0: no stalls
  double freeze_min_s = 0.3;
  double freeze_max_s = 2.0;

  bool active() const {
    return drop_fraction > 0.0 || late_fraction > 0.0 || jitter_s > 0.0 || repeat_fraction > 0.0 ||
           gap_every_s > 0.0 || freeze_every_s > 0.0;
  }
};
Performance with_frame_loss(Performance performance, const FrameLossOptions& options);

// A bigger or smaller dancer: skeleton offsets and every translation (root path included) times
// factor.
Performance with_body_scale(Performance performance, double factor);

// Another place and facing in the room: the root is turned by yaw_rad about the vertical axis
// through the world origin, then moved by offset_m.
Performance with_room_placement(Performance performance, double yaw_rad, const Vec3& offset_m);
// The world seen by a sensor whose floor is not level (a depth camera pitched down, a pose
// estimator's camera frame): every frame turned by `tilt_deg` about the X axis.
Performance with_world_tilt(Performance performance, double tilt_deg);
// What loading a file does to a full-body performance's world (load_motion: motion/up_axis.h):
// a floor tilted more than kLevelFromDeg over at least kLevelLeastSpanS, read from the body, is
// levelled; the recorded real wrists turn with it. Returns the levelling turn (the identity when
// nothing was levelled, and for a performance with no feet and head, as a three-point CSV has
// none).
Quat level_as_loaded(Performance& performance);
// The same for a performance to be delivered as three points (load_motion levels a three-point
// CSV from its head's path, head_path_levelling): read from the head joint's path, before the
// devices' offsets and tracking noise, and turned before any truth is recorded.
Quat level_head_path_as_loaded(Performance& performance);

// The same performance danced on another rig (a user's suit, avatar or another studio's skeleton):
// retargeted (duet::retarget_clip: role directions, stride-scaled root, feet on the floor) onto
// `rig`, a skeleton in metres whose roles are `rig_roles`. Times and truth are kept. Errors: roles
// the retargeting cannot use.
Result<Performance> with_rig(Performance performance, std::shared_ptr<const Skeleton> rig,
                             const JointRoles& rig_roles);

// What a headset and two controllers would report of the performance (issue 12): its head and
// wrists on the head-and-hands skeleton (duet/motion/head_hands.h), each point with its own
// tracking noise: normal per-axis position noise (standard deviation position_m) and a random
// rotation whose rotation vector has normal components (RMS angle rotation_deg).
struct PointNoiseOptions {
  double position_m = 0.005;
  double rotation_deg = 1.0;
  std::uint64_t seed = 1;
  // Where the devices sit against the joints (the eyes, the grips); zero: at the joints.
  DevicePointOffsets offsets;
  // What the follower is told of them and takes out after the noise, as `duet follow
  // --device-offsets-cm` and `duet serve` do (device_points_to_joints); zero: nothing.
  DevicePointOffsets taken_out;
  // A controller out of the headset's view, reported where it was last seen (its world pose,
  // noise included, held bit for bit, as our viewer sends it) while the head and the other hand
  // move on: spans of [stall_min_s, stall_max_s] seconds, one every stall_every_s on average,
  // each holding one hand, left and right in turn. 0: none.
  double stall_every_s = 0.0;
  double stall_min_s = 0.3;
  double stall_max_s = 2.0;
  // A controller's tracking glitch (the headset's cameras take one controller for the other or
  // lose its constellation for a frame): spans of [glitch_min_s, glitch_max_s] seconds, one
  // every glitch_every_s on average, in which one controller drawn at random is reported
  // glitch_min_m to glitch_max_m away from where it is, in one random direction. 0: none.
  double glitch_every_s = 0.0;
  double glitch_min_s = 0.01;
  double glitch_max_s = 0.05;
  double glitch_min_m = 0.1;
  double glitch_max_m = 0.4;
};
Result<Performance> with_head_hands(Performance performance, const PointNoiseOptions& noise);

// A composition of the above, applied in this order: play or improvise (at rate_hz), body scale,
// room placement, world tilt, another rig, sensor noise, levelling as a loaded file is levelled
// (full body only), head and hands, frame loss. Each stage's seed is
// derived from `seed`.
struct PerformanceRecipe {
  // A recorded performance (recorded_performance) performed instead of playing or improvising
  // from the sources; the perturbations below still apply. Its truth names its take.
  std::shared_ptr<const Performance> recorded;
  bool improvise = false;
  PlayOptions play;                    // when !improvise (seed ignored)
  ImproviseOptions improvise_options;  // when improvise (seed ignored)
  // The dancer's size against the template dancer's (with_body_scale). On another rig the body is
  // scaled after retargeting so that its standing height (measure_body) is this times the
  // template dancer's: body-size@rig is then the size it names whatever the rig's own size.
  // None: as delivered (on another rig, the rig's own body).
  std::optional<double> body_scale;
  double room_yaw_rad = 0.0;
  Vec3 room_offset_m = Vec3::Zero();
  double world_tilt_deg = 0.0;          // the sensor's world tilted (with_world_tilt)
  std::shared_ptr<const Skeleton> rig;  // null: the library's own rig
  JointRoles rig_roles;
  std::string rig_name;      // for reports ("asf", "bandai", ...)
  SensorNoiseOptions noise;  // seed ignored
  // Delivered as three points (head and hands) with point_noise (seed ignored).
  bool head_hands = false;
  PointNoiseOptions point_noise;
  // Three points: the follower is told the performer's head height standing (highest_head_m of
  // the performance before it is reduced to points: a height calibration) times this (1.05: one
  // 5 % off), Performance::told_head_height_m; 0: not told.
  double told_head_height_factor = 0.0;
  // Three points: the follower is told where the performer's wrists are with both arms held
  // straight forward (arms_forward_of_body of the performance on its rig: a body calibration),
  // each wrist moved by told_arms_forward_error (head heights; x outwards, y up, z forward: a
  // calibration pose held wider, higher or further), Performance::told_arms_forward.
  bool tell_arms_forward = false;
  Vec3 told_arms_forward_error = Vec3::Zero();
  FrameLossOptions loss;  // seed ignored
};

// sources[0] is the performed take (play); improvise draws from all of them; a recorded
// performance needs no sources. A recipe that would make more than kMaxClipFrames frames (a long
// duration at a high rate, a slow tempo) is an error before anything is made.
Result<Performance> make_performance(std::span<const SourceTake> sources,
                                     const PerformanceRecipe& recipe, std::uint64_t seed);

// A seed for one piece of an experiment (e.g. case index, take) from a base seed (splitmix64).
std::uint64_t derive_seed(std::uint64_t base, std::uint64_t a, std::uint64_t b = 0);

}  // namespace duet
