// The partner's pose, frame by frame (method.md 5 and 6): the response clip's pose at the
// estimated template frame, then the corrections, each switchable on its own:
//
//   response pose at frame f
//   -> align     root placed relative to the user's heading frame (5.1; filtered by smooth)
//   -> smooth    per-joint exponential smoothing in quaternion space (5.3)
//   -> footlock  planted feet held by a horizontal root shift (5.3)
//   -> contact   two-bone IK of each arm whose hand holds the user's (5.2)
//   -> blend     inertialization of the finished pose when the follower jumped (5.3); last, so
//                a jump's change made by any stage is blended (the IK would snap the arms)
//   -> reach     through that blend, a held hand reaches for the user's (contact and blend)
//   -> foothold  through that blend, planted feet held by leg IK (footlock and blend)
//   -> partner pose, root in the user's world frame
//
// Offline: PartnerModel (per duet take; may allocate and fail with a message).
// Run time: PartnerSynthesisJob with a PartnerContext sized once: allocates nothing, throws
// nothing, does no I/O. See docs/partner.md for every parameter and its default.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "duet/base/result.h"
#include "duet/motion/clip.h"
#include "duet/motion/skeleton_map.h"
#include "duet/partner/alignment.h"
#include "duet/partner/foot_hold.h"
#include "duet/partner/foot_lock.h"
#include "duet/partner/hand_contacts.h"
#include "duet/partner/jitter_meter.h"
#include "duet/partner/one_euro_filter.h"
#include "duet/partner/response_playhead.h"
#include "duet/partner/smoothing.h"
#include "duet/partner/steady_difference.h"

namespace duet {

// ---------------------------------------------------------------------------------------------
// Offline

struct PartnerModelOptions {
  ContactOptions contacts;
  // The ground height of each foot (its toe joint) is this quantile of the toe's height over the
  // response clip: robust to a floor that is not at y = 0 and to toe markers above the sole.
  double ground_quantile = 0.05;
};

// Everything the corrections need from one captured duet: the response skeleton and roles, the
// root placements (alignment), the hand contacts and the feet's ground heights. Immutable.
class PartnerModel {
 public:
  PartnerModel() = default;

  // template_clip/template_roles: the dancer the user dances; response_clip/response_roles: the
  // virtual partner. Same frame count and rate. The response roles must give two arm chains
  // (shoulder above elbow above wrist, neither arm below the other) and both toes. Errors say
  // what is missing.
  static Result<PartnerModel> build(const Clip& template_clip, const JointRoles& template_roles,
                                    const Clip& response_clip, const JointRoles& response_roles,
                                    const PartnerModelOptions& options = {});

  int frame_count() const noexcept { return alignment_.frame_count(); }
  double frame_rate() const noexcept { return contacts_.frame_rate(); }
  const Skeleton& response_skeleton() const noexcept { return *response_skeleton_; }
  const std::shared_ptr<const Skeleton>& response_skeleton_ptr() const noexcept {
    return response_skeleton_;
  }
  const JointRoles& response_roles() const noexcept { return response_roles_; }
  const SpatialAlignment& alignment() const noexcept { return alignment_; }
  const HandContacts& contacts() const noexcept { return contacts_; }
  // The standing heights (measure_body) of the captured template and response dancers, metres.
  double template_height_m() const noexcept { return template_height_m_; }
  double response_height_m() const noexcept { return response_height_m_; }
  // How much further apart the partner stands for a user `user_height_m` tall: the captured
  // spacing scales with the sum of the two dancers' heights (reach grows with size), so
  // (user + response) / (template + response); 1 when a height is unknown.
  double spacing_scale(double user_height_m) const noexcept;
  // Height (y, metres) of the response's toe joint when that foot stands on the floor.
  double foot_ground_height(Side side) const noexcept {
    return ground_heights_[static_cast<std::size_t>(side)];
  }
  // Whether the captured partner has that foot planted at `frame` (in [0, frame_count())): its
  // toe within thresholds.height_margin_m of the ground height and moving horizontally at most
  // thresholds.speed_threshold_mps since the previous frame (frame 0: towards the next one).
  bool foot_planted(int frame, Side side, const FootLockParams& thresholds) const noexcept;
  // Whether the response's legs are chains thigh (hip role) -> knee -> ankle -> toe, which the
  // foot hold (foot_hold.h) needs; without them it stays off.
  bool has_legs() const noexcept { return has_legs_; }
  // The 99th percentile over the captured partner's frames of its fastest joint's angular speed
  // (local rotations, End Sites left out), rad/s at the clip's rate.
  double captured_speed_p99_rad_s() const noexcept { return captured_speed_p99_rad_s_; }

 private:
  std::shared_ptr<const Skeleton> response_skeleton_;
  JointRoles response_roles_;
  SpatialAlignment alignment_;
  HandContacts contacts_;
  double template_height_m_ = 0.0;
  double response_height_m_ = 0.0;
  std::array<double, 2> ground_heights_{0.0, 0.0};
  bool has_legs_ = false;
  double captured_speed_p99_rad_s_ = 0.0;
  // Per frame and foot (frame * 2 + side): the captured toe's height above its ground height and
  // its horizontal speed, m and m/s.
  struct CapturedFoot {
    float height_above_ground_m = 0.0f;
    float speed_mps = 0.0f;
  };
  std::vector<CapturedFoot> captured_feet_;
};

// ---------------------------------------------------------------------------------------------
// Parameters

// Where the partner's wrist is sent while its hand holds the user's.
enum class IkTarget {
  // The captured wrist-to-wrist offset carried by the user's hand (position and rotation):
  // reproduces the captured grip, which matters when the skeletons only approximately touch.
  kCapturedOffset,
  // The user's wrist itself (the paper's target effector).
  kUserWrist,
};
bool parse_ik_target(std::string_view text, IkTarget& target);  // "offset" | "wrist"
const char* ik_target_name(IkTarget target);

struct PartnerParams {
  // The switches (method.md 5). All off: the output is the response pose unchanged.
  bool align = true;
  bool contact = true;
  bool smooth = true;
  bool foot_lock = true;
  bool blend = true;

  // smooth: half-lives of the per-joint exponential smoothing. The delay for a joint turning
  // steadily is at most half_life / ln 2 (22 ms at 0.015 s). Chosen on salsa 61_01, see
  // docs/partner.md: halves the jerk of a +-1 frame jittering estimate for ~1 cm of lag.
  double smooth_rotation_half_life_s = 0.015;
  double smooth_translation_half_life_s = 0.015;
  // smooth: the user's heading frame (root position on the floor and facing) goes through a
  // 1-euro filter before the partner is placed relative to it. A live sensor's root jitters by
  // ~1 cm and its heading by degrees per frame; placed relative to that, a partner 0.7 m away
  // skates by centimetres per frame. Still: cutoff 1 Hz; moving at 1 m/s (or turning at 1 rad/s):
  // 11 Hz, about 15 ms of lag. Measured (docs/evaluation.md, partner metrics): toe speed near the
  // ground 86 -> 58 cm/s on `improv-30hz-noisy`, 29 -> 31 cm/s on noise-free `improv-pause`.
  OneEuroParams user_filter;
  // smooth: under a noisy sensor the facing's jitter inflates the 1-euro filter's speed estimate,
  // and with it the cutoff, so the noise passes into the partner's hips (issue 11). The facing's
  // jitter is measured (jitter_meter.h, on its yaw) and the facing filter's beta divided by
  // 1 + (jitter / user_facing_jitter_reference_rad)^2: a clean capture's facing jitters by
  // 0.001-0.005 rad and keeps its responsiveness (beta 9.4-10), one with 4 degrees per axis of
  // noise by about 0.04 rad and is smoothed hard (beta 2). 0: no adaptation. Measured in
  // docs/evaluation.md ("Partner steadiness").
  double user_facing_jitter_reference_rad = 0.02;
  // smooth and align: the partner's heading turns at most this much faster than the template's
  // own heading turns at its frame (rad/s): a user's facing that is read to change at once (three
  // points at an improvised cut, where the head's yaw over the body differs between the two
  // moments; a tracking glitch) turned the whole partner at up to 2629 deg/s. 0: no limit.
  double facing_max_turn_rad_s = 6.0;
  // smooth: what the 1-euro filter smooths is the user's heading relative to the template's at
  // the partner's frame (the facing as a turn from the template's, the position as a shift from the
  // template's pelvis), which holds still while the user dances the template, turns and steps
  // included, rather than the heading itself, whose filtering lags every turn and step of the
  // dance (issue 11: "filter the correction, not the target"). At a jump the filters carry on
  // from the heading they showed. Measured in docs/evaluation.md ("The heading relative to the
  // template"). false: the heading itself.
  bool smooth_relative_to_template = true;
  // smooth: the correction the contact IK adds to the captured arm (per arm joint, the rotation
  // from the captured local rotation to the IK's, as a rotation vector) goes through a 1-euro
  // filter: 1 Hz still, +1 Hz per rad/s the correction changes at. The IK otherwise carries every
  // jitter of the user's wrist into the partner's arm, near full extension magnified into
  // forearm flicks (issue 11: p99 largest joint speed 1703 deg/s against 529 captured). The
  // correction, not the target, is filtered, so the captured arm's own motion keeps its detail
  // and only the slowly varying difference between the two bodies lags. Measured in
  // docs/evaluation.md ("Partner steadiness"). Restarts at a jump (the blend takes the jump).
  OneEuroParams ik_correction_filter{1.0, 1.0, 1.0};
  // smooth: and the filtered correction changes at most this fast (rad/s, per joint), so the IK
  // adds at most this to any arm joint's angular speed (infinity: no limit). Noise makes the
  // 1-euro filter's speed estimate, and so its cutoff, rise; the limit holds regardless.
  // Measured (docs/evaluation.md, "Partner steadiness"): with it the partner's p99 largest joint
  // speed is about what it is with the IK off; 2 rad/s was as steady but slowed a persistent
  // correction (`body-size`: median hand error 1.25 cm, 0.99 at 4 rad/s).
  double ik_correction_max_speed_rad_s = 4.0;
  // smooth: and by no more than the captured arm joint's own speed leaves of this budget (rad/s),
  // but at least ik_correction_min_speed_rad_s: where the captured arm already swings fast the
  // correction waits for it. Added at its full 4 rad/s on top of a fast swing it raised the p99
  // largest joint speed of a user of another body to 1.2x the captured partner's (`partner-role`
  // on the ASF rig and a game avatar; docs/evaluation.md, "The IK's correction waits for a fast
  // swing"). Infinity: no budget.
  double ik_correction_speed_budget_rad_s = 8.0;
  double ik_correction_min_speed_rad_s = 1.0;
  // smooth: the correction filter's cutoff falls as the IK target's measured jitter grows:
  // this on a clean sensor, ik_correction_filter.min_cutoff_hz * ik_target_jitter_reference_m /
  // jitter between, ik_correction_filter's own from the reference up. 0 (or at most
  // min_cutoff_hz): the filter as given. Measured in docs/evaluation.md ("The IK's correction
  // filtered by the noise").
  double ik_correction_clean_cutoff_hz = 10.0;
  // contact: the arms' IK eases the last share of the arm's length (IkTwoBoneJob::soft_reach):
  // near a straight arm the elbow turns ever faster per centimetre the target moves, so a target
  // at the edge of the reach (a larger user, a hand further out than the capture's) snapped the
  // elbow. Measured in docs/evaluation.md ("Soft reach"): `harsh@asf` p99 largest joint speed
  // 1.11x -> 1.09x the captured partner's, `body-size@asf` hand 1.58 -> 1.35 cm. 0: hard reach.
  double ik_soft_reach = 0.08;
  // smooth: under a noisy sensor the user's wrist, and with it the IK target, jitters (at 4
  // degrees per joint and axis by 6-9 cm a frame), and the IK passed it into the partner's arm
  // (issue 11: the hand 6.7 cm from the user's real hand at 60 Hz, 1.4 cm with the IK off). What
  // the target adds to the captured partner's wrist is the difference between the two bodies:
  // slowly varying, and per hand pair alike from one contact to the next. It is averaged in the
  // user's body frame, per hand pair and kept across contacts, over a time that grows with the
  // target's measured jitter (jitter_meter.h): ik_difference_time_constant_s * x / (1 + x), x =
  // (jitter / ik_target_jitter_reference_m)^4, so a clean capture (1-3 mm) is not delayed and a
  // noisy one is averaged over about that long; the IK aims at the captured wrist plus the
  // average. 0: the sensed target as it is. Measured in docs/evaluation.md ("Partner
  // steadiness").
  double ik_target_jitter_reference_m = 0.02;
  double ik_difference_time_constant_s = 0.1;
  // smooth: the average is trusted by the share of its power that is not the sensor's noise,
  // the power measured over this long (steady_difference.h: near 1 on a clean sensor, towards
  // the captured arm where the noise is as large as the difference); 0: trusted whole.
  double ik_difference_power_time_constant_s = 1.0;
  // smooth and align: the captured offset from the user's hand to the partner's (10-30 cm) is
  // carried by the template's hand turned into the user's heading plus the steady difference
  // (as above) of the user's sensed hand turn from it, not by the sensed turn itself, whose
  // noise (every joint's above the hand) swung the offset by centimetres. false: by the sensed
  // turn. Measured in docs/evaluation.md ("What the hand's difference is trusted for").
  bool steady_hand_turn = true;
  // align and contact: through frames without evidence (a stalled sensor, a pose missing, an
  // outlier the follower set aside: a tracker's pop) the user is carried on from where last seen as
  // the template dancer moves, body and hands (UnseenUser, used by LiveLoop), instead of standing
  // frozen where the sensor stopped while the partner dances on. false: the held pose as it is.
  // Measured in docs/evaluation.md ("A sensor that stalls").
  bool carry_unseen_user = true;
  // smooth: the response is shown at a real frame that advances at the dancer's tempo
  // (response_playhead.h; used by LiveLoop, which samples the pose there and passes it as
  // PartnerSynthesisJob::frame_position).
  PlayheadParams playhead;

  // blend: half-life of the inertialization offset recorded at a jump, and the caps on how fast
  // an offset may change (the paper's velocity-based blending, 5.3): per joint rotation, and the
  // root's place relative to the user (e.g. from holding hands to 2 m apart; without a cap a 2 m
  // change crossed the room at 10 m/s). 6 rad/s (344 deg/s) is well below the 99th percentile of
  // the captured salsa partners' per-frame largest joint speed (626 deg/s over the eval's takes);
  // 4 m/s is above their 99th percentile root speed (3.1 m/s over 61_*), as a partner that
  // jumped has ground to make up. Issue 11 (the partner back in place within 0.3 s of a jump),
  // measured with `duet eval` (docs/evaluation.md, "Partner steadiness"): from 0.1 s, 4 rad/s,
  // 3 m/s the median time to rejoin hands and spacing on `improv` went 0.43 -> 0.23 s (jumps
  // rejoined within 0.3 s 9 -> 13 of 23) and the mean joint error 5.6 -> 4.5 cm, for a p99
  // largest joint speed of 1.00 -> 1.02x the captured partner's. 8 rad/s rejoined 17 of 23 in
  // time but took `noise-sweep-1` to 1.13x.
  double blend_half_life_s = 0.05;
  double blend_max_speed_rad_s = 6.0;
  double blend_max_root_speed_mps = 4.0;
  // How the caps hold. true: the offsets decay with blend_half_life_s but none moves faster
  // than its cap (PoseInertializer::update's limits): a far jump crosses at the cap and arrives
  // (issue 11: the partner at its new place within 0.3 s). false: the half-life is stretched
  // until the decay alone stays under the caps (the earlier behaviour), which leaves a long
  // tail: a 0.7 m change took 0.6 s to come within 5 cm. Measured in docs/evaluation.md
  // ("Partner steadiness").
  bool blend_speed_limited = true;
  // With blend_speed_limited: an offset also changes no faster than keeps each joint shown
  // turning at most as fast as the captured pose under it turns, or blend_max_speed_rad_s,
  // whichever is faster (PoseInertializer::Limits::limit_shown_speed). The caps alone let the
  // blend's 6 rad/s add to a joint the capture already turns fast, and on improvised dances the
  // partner's p99 largest joint speed reached 1.11-1.14x the captured partner's on takes the
  // tuning had not seen (issue 11's 1.1x). Measured in docs/evaluation.md ("A blend no faster
  // than the capture"): at most 1.07x on every improvised and noisy case of two take sets.
  bool blend_no_faster_than_input = true;
  // ... but the partner's facing (the root's rotation) may turn this much faster than the
  // capture: held through a spin, it kept the partner turned away for the spin's whole length
  // (a held hand 16 cm off 1 s after a jump, `bvh_output_in_blender_and_threejs`). 0: held like
  // every joint.
  double blend_root_catch_up_rad_s = 2.0;
  // blend with contact: through a jump's blend an arm whose hand holds the user's reaches for it
  // (stage 5b) instead of waiting for the blend, which kept held hands apart for up to 0.7 s
  // after jumps that barely moved the partner (issue 11: hands rejoined within 0.3 s). A second
  // IK on the blended pose, its weight rising over reach_s after the jump (smoothstep) and
  // falling as the blend's hold on the wrist (its distance from where the contact IK put it)
  // drops below reach_fade_m; what it adds to an arm joint changes at most
  // reach_max_speed_rad_s. reach_s = 0: off. Measured with `duet eval` (docs/evaluation.md,
  // "Hands first after a jump"): jumps rejoined within 0.3 s 108 -> 132 of 228 over the
  // improvised and noise-sweep cases, for a p99 largest joint speed at most 0.02x the captured
  // partner's higher. 4 -> 6 rad/s with blend_no_faster_than_input, which holds the arms' blend
  // back where the capture turns them fast and so leaves the reach more to do (docs/evaluation.md,
  // "A blend no faster than the capture").
  double reach_s = 0.3;
  double reach_fade_m = 0.1;
  double reach_max_speed_rad_s = 6.0;

  // contact: IK target and the time the IK weight takes to go from 0 to 1 (and back) when a
  // contact starts (ends). The weight follows a smoothstep of that linear ramp.
  IkTarget ik_target = IkTarget::kCapturedOffset;
  double ik_fade_s = 0.25;
  // contact: the IK target is kept continuous (5.3 blending applied to the target): when the
  // follower jumps, when a hand changes the hand it holds, or when the target moves faster than
  // this (the user's wrist teleported: a sensor glitch, or a synthetic performance's cut), the
  // jump of the target is absorbed by an offset that decays like the blend (blend_half_life_s);
  // at a follower jump with blend on, the blend takes it instead.
  // Without it the IK snaps the arm in one frame (measured: ~5000 deg/s at salsa jumps,
  // docs/evaluation.md "Partner metrics"). Hands move at most ~3-4 m/s in the salsa takes; 10 m/s
  // stays above a noisy sensor's wrist jitter (3 deg per joint at 30 Hz: ~3 m/s RMS). The
  // offset's half-life is stretched like the blend's so that it alone moves the target at most
  // ik_target_max_blend_speed_mps (about blend_max_speed_rad_s times an arm's length).
  double ik_target_jump_speed_mps = 10.0;
  double ik_target_max_blend_speed_mps = 2.0;

  // footlock thresholds and release.
  FootLockParams foot;
  // footlock with blend: false, the default, locks no foot while a blend carries the body to a
  // new place (from a jump's frame until the blend's offsets are under 0.02 rad and 1 cm); the
  // locks start again where the blend has brought the feet. A lock held through the blend pinned
  // the feet against the user's sensor noise and kept the root up to foot.max_offset_m off the
  // place the blend was bringing it to: under 4 degrees of noise per axis the spacing 0.3 s after
  // a jump was 3.2 cm off in the median instead of 1.3, and jumps rejoined within 0.3 s over the
  // improvised and noisy cases on five rigs rose 350 -> 389 of 938 (docs/evaluation.md, "Feet
  // free while the blend carries them", session 29). true: the earlier behaviour.
  bool foot_lock_through_blend = false;
  // foothold (with footlock and blend): planted feet held by leg IK through a jump's blend,
  // catching up by steps (foot_hold.h). enabled = false: the blend slides them.
  FootHoldParams foot_hold;

  // Empty when valid; otherwise which parameter is wrong (negative or non-finite times, ...).
  std::string validate() const;
};

// The six switchable corrections by name, in the order corrections_string() lists them (the
// names of `--corrections`, `duet eval`'s rows and the protocol's `set`, docs/protocol.md).
inline constexpr std::string_view kCorrectionNames[] = {"align",    "contact", "smooth",
                                                        "footlock", "blend",   "foothold"};
// Sets one switch of `params` by name; false (and params untouched) for an unknown name.
bool set_correction(PartnerParams& params, std::string_view name, bool enabled) noexcept;
// Whether the switch `name` is on; false for an unknown name.
bool correction_enabled(const PartnerParams& params, std::string_view name) noexcept;
// The known names joined by ", " (for messages that list them).
std::string correction_names_list();

// Sets the six switches from a comma-separated list of the corrections to turn on:
// "align,contact,smooth,footlock,blend,foothold", "all" or "none". Unknown names are an error that
// lists the known ones; params is untouched on error.
Status parse_corrections(std::string_view list, PartnerParams& params);
// The switches that are on, as a list parse_corrections() accepts ("none" when all are off).
std::string corrections_string(const PartnerParams& params);

// How far the contact IK's correction of an arm joint may turn in a frame of dt_s seconds
// (radians), the captured joint having turned by captured_move_rad since the frame before: at
// most ik_correction_max_speed_rad_s, no more than what the captured turn leaves of
// ik_correction_speed_budget_rad_s, at least ik_correction_min_speed_rad_s (never over the most).
// A captured turn that is not a finite number counts as none.
double ik_correction_step_limit(const PartnerParams& p, double dt_s,
                                double captured_move_rad) noexcept;
// A correction (rotation vector) put on a joint's base rotation as base * exp(correction), last
// shown as `previous`: `shown` stepped towards `wanted` by at most most_rad, and no further than
// keeps the joint's turn since `previous` within budget_rad, or within what it turns with the
// correction kept plus least_rad where that is more. A correction against the base's own turn is
// free; one along it takes what the turn leaves of the budget (the reach through a jump's blend).
Vec3 step_within_turn(const Vec3& shown, const Vec3& wanted, double most_rad, const Quat& base,
                      const Quat& previous, double budget_rad, double least_rad) noexcept;

// ---------------------------------------------------------------------------------------------
// Run time

// What the corrections read from the user's current world pose. Indexed by Side.
struct UserPose {
  Vec3 root_position_ws = Vec3::Zero();
  Quat root_rotation_ws = Quat::Identity();
  // The rig-independent heading frame the partner is placed in (body_heading_frame: the pelvis
  // centre on the floor, the hip line's heading); valid = false falls back to the root's.
  Transform body_heading;
  bool body_heading_valid = false;
  // The user's standing height (measure_body), metres; 0 = unknown: the partner keeps the
  // captured spacing. Otherwise the spacing is scaled to fit the two bodies (see PartnerModel).
  double height_m = 0.0;
  std::array<Vec3, 2> wrist_positions_ws{Vec3::Zero(), Vec3::Zero()};
  std::array<Quat, 2> wrist_rotations_ws{Quat::Identity(), Quat::Identity()};
  // Where the user's body alone puts each wrist against the template dancer's at the partner's
  // frame, relative to the heading frame (WristsOnUserBody). The contact IK's steady difference
  // (smooth, align) averages only what the sensed hand differs by beyond it. Zero: one body.
  std::array<Vec3, 2> wrist_body_difference_hs{Vec3::Zero(), Vec3::Zero()};
};

// Reads a UserPose from world transforms of the user's skeleton (forward_kinematics output):
// root = joint 0, wrists = the wrist roles. The user's skeleton should follow the template's
// axis conventions (heading and hand frames are compared across them).
UserPose user_pose_from_world(std::span<const Vec3> positions_ws,
                              std::span<const Quat> rotations_ws, const JointRoles& roles) noexcept;

// How a hand joint's frame differs between two rigs (issue 10), per Side. The grip offsets
// (IkTarget::kCapturedOffset) are held in the template hand's frame; on the user's rig a vector v
// of that frame is R_user_hand * turn * v in the world. A BVH or ASF rig's joint frames are the
// world's in its rest pose, so a rig whose rest pose holds the arms otherwise than the
// template's (an A-pose against the capture's T-pose) has its hands turned by the turn between
// the two rest forearms (elbow -> wrist, the smallest arc); a twist about the forearm is not seen
// there. Identity for a side whose elbow or wrist either rig lacks.
std::array<Quat, 2> hand_frame_turns(const Skeleton& user, const JointRoles& user_roles,
                                     const Skeleton& template_skeleton,
                                     const JointRoles& template_roles);

// State kept between frames, sized once for a skeleton. One context per partner being
// synthesised; it may be used with every PartnerModel whose response skeleton has that many
// joints (e.g. all takes of a library: moving to another take is a jump).
class PartnerContext {
 public:
  PartnerContext() = default;
  explicit PartnerContext(int joint_count) { resize(joint_count); }
  void resize(int joint_count);  // allocates; also resets
  // Forget the past: the next frame starts fresh (no smoothing history, no blend offsets, no
  // locks, IK weights at 0).
  void reset() noexcept;
  int joint_count() const noexcept { return static_cast<int>(blend_rotations_.size()); }
  // An arm's contact IK still has weight (a contact held or fading out) after the last frame.
  bool arm_ik_weighted() const noexcept { return ik_ramp_[0] > 0.0 || ik_ramp_[1] > 0.0; }

 private:
  friend struct PartnerSynthesisJob;

  bool primed_ = false;
  PoseInertializer inertializer_;
  PoseSmoother smoother_;
  FootLocker foot_locker_;
  FootHold foot_hold_;
  std::vector<Vec3> blend_translations_;  // output of the blend stage last frame
  std::vector<Quat> blend_rotations_;
  std::vector<Vec3> positions_ws_;  // forward kinematics scratch
  std::vector<Quat> rotations_ws_;
  Transform user_heading_;  // last finite user heading frame
  // The user's heading frame through the 1-euro filter (smooth): root position on the floor and
  // facing direction (a unit horizontal vector, so the yaw never wraps).
  OneEuroFilter3 user_root_filter_;
  OneEuroFilter3 user_facing_filter_;
  // The filters hold the user's heading relative to the template's (smooth_relative_to_template),
  // and the template's heading rotation it was taken against last frame.
  bool heading_is_relative_ = false;
  Quat template_rotation_ = Quat::Identity();
  // The jitter (radians) of the filtered facing's yaw, after adding this frame's facing.
  double facing_jitter(const Vec3& facing, double dt) noexcept;
  JitterMeter user_facing_jitter_;  // of the yaw of the facing filtered (relative or raw), rad
  double user_facing_yaw_ = 0.0;    // that facing's yaw, unwrapped
  bool user_facing_yaw_valid_ = false;
  // Per response hand, per arm joint (shoulder, elbow): the IK's correction (smooth).
  std::array<std::array<OneEuroFilter3, 2>, 2> ik_correction_filter_;
  std::array<std::array<Vec3, 2>, 2> ik_correction_{};  // their outputs last frame
  // The captured arm joints' rotations the last frame the IK corrected them (the budget).
  std::array<std::array<Quat, 2>, 2> ik_captured_previous_{};
  std::array<bool, 2> ik_captured_previous_valid_{};
  // How far the captured arm joint `joint` (0 shoulder, 1 elbow) of `hand` turned since it was
  // last corrected (0 the first frame), remembering `captured` for the next frame.
  double captured_arm_turn(std::size_t hand, std::size_t joint, const Quat& captured) noexcept;
  // The IK target under a noisy sensor: the captured wrist plus the average, in the user's body
  // frame, of what the sensed target adds to it, trusted by its real share (steady_difference.h).
  Vec3 steady_ik_target(std::size_t hand, const Vec3& target, const Vec3& captured_wrist,
                        const Quat& body_rotation, const PartnerParams& p, double dt,
                        bool restart) noexcept;
  std::array<SteadyDifference, kHandPairCount> ik_difference_;  // per hand pair, across contacts
  // The rotation that carries the captured offset: the template's hand turned into the user's
  // heading, plus the steady difference of the user's sensed hand turn from it (a rotation
  // vector in the template hand's frame, per hand pair).
  Quat steady_hand_turn(std::size_t hand, const Quat& sensed, const Quat& captured, double offset_m,
                        const PartnerParams& p, double dt, bool restart) noexcept;
  std::array<SteadyDifference, kHandPairCount> ik_turn_difference_;
  std::array<std::array<JitterMeter, 3>, 2> ik_turn_jitter_;  // per hand, per axis, radians
  // The jitter (metres, RMS over the axes) of each response hand's raw IK target, after adding
  // this frame's target; restart: the target moved on (a jump, another hand held).
  double ik_target_jitter(std::size_t hand, const Vec3& target, double dt, bool restart) noexcept;
  // The filtered facing turn from the template's heading, held so that the heading shown turns
  // from last frame's (user_heading_) at most by the template's own turn plus extra_rad
  // (PartnerParams::facing_max_turn_rad_s times the frame's time).
  Quat capped_facing_turn(const Quat& turn, const Quat& template_rotation,
                          const Quat& previous_template_rotation, double extra_rad) const noexcept;
  std::array<std::array<JitterMeter, 3>, 2> ik_target_jitter_;  // per hand, per axis
  std::array<double, 2> ik_ramp_{0.0, 0.0};  // per response hand, linear fade state in [0, 1]
  std::array<int, 2> ik_pair_{-1, -1};       // pair that last drove that hand
  // IK target continuity, per response hand: last frame's raw and shown targets (valid when the
  // IK ran last frame) and the decaying offset between what is shown and the raw target.
  std::array<bool, 2> ik_target_valid_{false, false};
  std::array<Vec3, 2> ik_raw_target_{Vec3::Zero(), Vec3::Zero()};
  std::array<Vec3, 2> ik_shown_target_{Vec3::Zero(), Vec3::Zero()};
  std::array<Vec3, 2> ik_target_offset_{Vec3::Zero(), Vec3::Zero()};
  std::array<Vec3, 2> ik_target_offset_velocity_{Vec3::Zero(), Vec3::Zero()};
  std::array<double, 2> ik_target_half_life_{0.0, 0.0};
  double blend_half_life_ = 0.0;  // of the current transition
  bool blend_carrying_ = false;   // the blend still over 0.02 rad or 1 cm after its last update
  // The current transition's detour round the user (heading frame; zero: none) and the root's
  // translation offset when it started (the detour's progress is measured against it).
  Vec3 detour_hs_ = Vec3::Zero();
  double detour_offset_m_ = 0.0;
  double detour_peak_ = 0.5;  // the blend's progress at which the detour is fullest
  std::array<Vec3, 2> ik_reached_ws_{Vec3::Zero(), Vec3::Zero()};  // wrist after the contact IK
  std::array<double, 2> reach_ramp_{1.0, 1.0};  // per response hand, since the last jump
  // Per response hand, the arm joints (shoulder, elbow) as shown last frame (the reach's budget).
  std::array<std::array<Quat, 2>, 2> reach_shown_previous_{};
  std::array<bool, 2> reach_shown_previous_valid_{};
  // Per foot, what the foot hold adds to the leg joints (hip, knee, ankle) as shown, and the
  // joints as shown last frame (its speed budget).
  std::array<std::array<Vec3, 3>, 2> hold_correction_{};
  std::array<std::array<Quat, 3>, 2> hold_previous_{};
  std::array<bool, 2> hold_previous_valid_{};
  std::array<std::array<Vec3, 2>, 2> reach_correction_{
      {{Vec3::Zero(), Vec3::Zero()},
       {Vec3::Zero(), Vec3::Zero()}}};  // per hand, shoulder and elbow
};

// Per-frame diagnostics (optional output).
struct PartnerFrameInfo {
  std::uint8_t contact_mask = 0;  // captured contacts at this frame (bit = hand pair)
  // Per response hand (Side): IK weight after the fade (0: no IK), the target the wrist was sent
  // to, and the wrist's distance to it after the IK (both meaningful only when weight > 0).
  std::array<double, 2> ik_weight{0.0, 0.0};
  std::array<Vec3, 2> ik_target_ws{Vec3::Zero(), Vec3::Zero()};
  std::array<double, 2> ik_error_m{0.0, 0.0};
  std::array<bool, 2> foot_locked{false, false};  // per foot (Side)
  std::array<bool, 2> foot_held{false, false};    // held through a blend or stepping (foot_hold.h)
  Vec3 foot_lock_offset_ws = Vec3::Zero();        // horizontal root shift applied
  double blend_offset_rad = 0.0;  // largest joint rotation offset still being blended out
};

// One frame of partner synthesis. A plain struct in the style of ozz-animation's jobs: set the
// inputs, call run(). Pointers are not owned.
struct PartnerSynthesisJob {
  // ---- Inputs ----
  const PartnerModel* model = nullptr;
  const PartnerParams* params = nullptr;
  // Estimated template frame (FollowResult::frame_in_take), in [0, model->frame_count()).
  int frame = -1;
  // The real frame the pose was sampled at (ResponsePlayhead), used for the root's placement;
  // < 0 or not finite: `frame`.
  double frame_position = -1.0;
  // The follower jumped this frame (FollowResult::jumped, or a change of take): blend starts.
  bool jumped = false;
  // Time since the previous frame, seconds; <= 0 or not finite counts as one model frame.
  double dt_s = 0.0;
  // The response clip's local pose at `frame` (or sampled near it), one entry per joint.
  std::span<const Vec3> translations_ls;
  std::span<const Quat> rotations_ls;
  // The user's current world pose; required when params->align or params->contact. Non-finite
  // values are tolerated: alignment keeps the last finite heading, IK skips that hand.
  const UserPose* user = nullptr;
  // State between frames; joint_count() must match the model's response skeleton.
  PartnerContext* context = nullptr;

  // ---- Outputs (caller-owned; may alias translations_ls / rotations_ls) ----
  // The partner's local pose; the root's local transform is in the user's world frame (in the
  // capture's world frame when align is off).
  std::span<Vec3> translations_ls_out;
  std::span<Quat> rotations_ls_out;
  PartnerFrameInfo* info = nullptr;  // optional

  // Empty when the job can run, else what is wrong ("model is null", "frame is outside the
  // model's frames", ...).
  std::string_view validate() const noexcept;
  // Validates, then runs every switched-on correction. Returns false (outputs untouched) when
  // validate() fails.
  bool run() const noexcept;
};

}  // namespace duet
