// Feet held through a jump's blend (issue 11: no foot sliding after a jump).
//
// At a follower jump the blend (inertialization, smoothing.h) carries the whole finished pose
// from where it was to the new frame's: the root crosses to its new place at up to 3 m/s and
// every leg joint turns at up to 4 rad/s, so a foot the captured partner has planted slid with
// them (docs/evaluation.md, "Feet through a jump": up to 7.9 m/s on `improv-pause`). The foot
// lock (foot_lock.h) cannot hold them: it shifts the whole root, before the blend, by at most
// 0.15 m.
//
// Here, after the blend, each planted foot's ankle is held where it stood (horizontally, with
// its heading; its height and tilt stay the pose's) and the leg reaches it by two-bone IK. At the
// jump itself every foot is held where it stands (one the new frame has in the air steps from
// there at once). The pose moves on under the held feet; they catch up by steps of their own:
// the ankle rises by `step_height_m` (a sine arc over `step_time_s`), crosses to where the pose
// puts it plus the body's travel over `step_lead_s` (it lands ahead, as in walking, within the
// leg's reach), and is held there. A held foot steps
// - when the captured foot lifts (crossing at floor level along the capture's own swing dragged
//   the foot whenever the capture's plant flickered);
// - when the pose has left it more than `step_trigger_m` behind in the body's direction of travel
//   (only one foot at a time, unless the other is twice that behind);
// - when it is further from its hip than `reach_fraction` of the leg and than the pose has it (a
//   straight leg drags it).
// A step that lands while the captured foot is in the air goes on, without lift, to where the
// pose has it, and the foot is free; should the captured foot plant again first, it is held
// where it is and the rest is a step of its own (crossing on along the floor slid it). Holds start
// only while the blend is under way; once it is over, a held foot is let go when the pose has
// caught up with it (within 5 mm) or steps when the captured foot lifts.
//
// This class decides where each ankle goes; PartnerSynthesisJob runs the leg IK. Allocation-
// free and noexcept.
#pragma once

#include <array>
#include <string>

#include "duet/math/types.h"

namespace duet {

struct FootHoldParams {
  // On by default since session 47: it takes the slides after jumps down (full body, 20 noisy
  // cells: frames with a planted toe over 0.3 m/s 14373 -> 9448) within the capture's joint
  // speed (the speed budget below, session 46; without it the steps took the p99 of the largest
  // joint speed to 1.10-1.43x the captured partner's). docs/evaluation.md, "Feet through a jump"
  // and "The foot hold within a speed budget". `--no-foot-hold`, `duet eval`'s `no-foothold` row.
  bool enabled = true;
  // Chosen with `duet eval` on improv-pause / improv-30hz-noisy / harsh (docs/evaluation.md,
  // "Feet through a jump"): a salsa step is 0.2-0.4 m; the root crosses at up to 3 m/s.
  double step_trigger_m = 0.2;  // how far the pose may leave a held foot before it steps
  double step_time_s = 0.25;    // length of a step
  double step_height_m = 0.08;  // how high a step of its own lifts the ankle
  // A held foot further from its hip than this share of the leg's length (and than the pose puts
  // it) steps too, also with the other foot in the air: a straight leg would drag it.
  double reach_fraction = 0.95;
  // A step of its own lands ahead of where the pose puts the foot by the body's travel over this
  // time (within the leg's reach), as in walking, so the body passes over it.
  double step_lead_s = 0.1;
  // What the hold adds to each leg joint (hip, knee, ankle) turns the joint as shown no faster
  // than speed_budget_rad_s since the frame before, or than the joint turns without it plus
  // least_speed_rad_s where that is more (step_within_turn), also when a hold ends. Without it the
  // steps took the partner's p99 largest joint speed to 1.10-1.26x the captured partner's; with
  // 8 rad/s it is what it is without the hold, the slides kept two thirds down (docs/evaluation.md,
  // "The foot hold within a speed budget"). Infinity: no budget.
  double speed_budget_rad_s = 8.0;
  double least_speed_rad_s = 1.0;

  // Empty when valid; otherwise which field is wrong.
  std::string validate() const;
};

// Where one ankle goes this frame.
struct FootHoldTarget {
  bool active = false;              // false: the foot stays where the pose puts it
  Vec3 position_ws = Vec3::Zero();  // the ankle's position
  // Turn about the vertical applied on the left of the pose's ankle world rotation: a held foot
  // keeps its heading (its tilt stays the pose's); a step turns it back.
  Quat turn_ws = Quat::Identity();
};

class FootHold {
 public:
  void reset() noexcept;

  // Per foot (Side order): ankles_ws / ankle_rotations_ws, where the finished pose puts each
  // ankle; hips_ws, where it puts the thigh joint, and leg_lengths_m, thigh + shin; planted, the
  // captured plant at the shown frame. blending: the jump's blend is under way (holds start only
  // then); jumped: it starts this frame, and every foot is held where it stands (a foot the new
  // frame has in the air steps from there at once). dt_s > 0.
  void update(const std::array<Vec3, 2>& ankles_ws, const std::array<Quat, 2>& ankle_rotations_ws,
              const std::array<Vec3, 2>& hips_ws, const std::array<double, 2>& leg_lengths_m,
              const std::array<bool, 2>& planted, bool blending, bool jumped,
              const FootHoldParams& params, double dt_s) noexcept;

  const FootHoldTarget& target(int foot) const noexcept {
    return targets_[static_cast<std::size_t>(foot)];
  }
  bool held(int foot) const noexcept { return feet_[static_cast<std::size_t>(foot)].state != kFree; }
  bool stepping(int foot) const noexcept {
    return feet_[static_cast<std::size_t>(foot)].state == kStepping;
  }

 private:
  enum State { kFree, kHeld, kStepping };
  struct Foot {
    State state = kFree;
    Vec3 point = Vec3::Zero();          // held point (x, z used), or the step's start
    Quat rotation = Quat::Identity();   // held world rotation, or the step's start
    Vec3 landing = Vec3::Zero();        // the step's landing point once fixed
    bool landing_fixed = false;
    double lift_m = 0.0;                // this step's added height (0: released into the swing)
    double progress = 0.0;              // of the step, 0..1
    // The held heading less the pose's (radians about the vertical), unwrapped from frame to frame.
    double heading = 0.0;
  };
  void start_step(Foot& foot, double lift_m) noexcept;
  void hold(Foot& foot, const Vec3& point, const Quat& rotation) noexcept;

  std::array<Foot, 2> feet_{};
  // Where each ankle was shown last frame (the target, or the pose when free), valid after a
  // frame with finite input: a jump holds the feet there.
  std::array<Vec3, 2> shown_{Vec3::Zero(), Vec3::Zero()};
  std::array<Quat, 2> shown_rotations_{Quat::Identity(), Quat::Identity()};
  std::array<bool, 2> shown_valid_{false, false};
  Vec3 centre_ = Vec3::Zero();  // the hips' midpoint last frame
  bool has_centre_ = false;
  Vec3 body_velocity_ = Vec3::Zero();
  std::array<FootHoldTarget, 2> targets_{};
};

}  // namespace duet
