// A height calibration in VR (docs/protocol.md, `head_height`): standing straight, the user
// holds both controllers' grip buttons for a second, and the headset's height goes to the server,
// which then knows the user's size from the first step instead of learning it from the highest
// the head has held (a dance that starts low fools that for its first seconds). Held with both
// arms straight forward, the same hold also calibrates the body (`arms_forward`): where this body
// holds its hands, which another body's shoulders and head place differently.

/** How long both grips must be held, so a grab in the dance does not calibrate. */
export const kCalibrationHold_ms = 1000;
/** The heights the server takes (duet serve --head-height's range), metres. */
export const kHeadHeightRange_m = [0.6, 2.6];

/**
 * True when both controllers' grip (squeeze) buttons are pressed. WebXR's 'xr-standard'
 * gamepad mapping puts the squeeze at buttons[1].
 */
export function bothGripsSqueezed(session) {
  let left = false;
  let right = false;
  for (const source of session?.inputSources ?? []) {
    const pressed = source.gamepad?.buttons?.[1]?.pressed === true;
    if (source.handedness === 'left') left = left || pressed;
    if (source.handedness === 'right') right = right || pressed;
  }
  return left && right;
}

/**
 * Whether an `xr_pose` message (docs/protocol.md) shows both arms held forward: each grip at
 * least 0.3 m in front of the headset along where it looks, between 0.6 m below and 0.15 m above
 * it. The server checks the pose again (in head heights); this keeps a height-only calibration,
 * arms down, from asking for one.
 */
export function armsHeldForward(pose) {
  const [w, x, y, z] = pose?.head?.orientation ?? [];
  const head = pose?.head?.position;
  if (![w, x, y, z].every(Number.isFinite) || !head) return false;
  // The headset looks along -Z of its orientation: that axis in the room, made level.
  let fx = -2 * (x * z + w * y);
  let fz = -(1 - 2 * (x * x + y * y));
  const length = Math.hypot(fx, fz);
  if (!(length > 1e-6)) return false;
  fx /= length;
  fz /= length;
  for (const hand of [pose.left?.position, pose.right?.position]) {
    if (!hand || !hand.every(Number.isFinite)) return false;
    const ahead = (hand[0] - head[0]) * fx + (hand[2] - head[2]) * fz;
    const rise = hand[1] - head[1];
    if (!(ahead >= 0.3 && rise >= -0.6 && rise <= 0.15)) return false;
  }
  return true;
}

/**
 * A buzz in both controllers: the calibration was sent, short for the height alone, long for the
 * height and the body (arms held forward). Headsets without haptics: none.
 */
export const kBuzzHeight_ms = 120;
export const kBuzzBody_ms = 400;
function buzz(session, ms) {
  for (const source of session?.inputSources ?? []) {
    const actuator = source.gamepad?.hapticActuators?.[0];
    if (typeof actuator?.pulse === 'function') actuator.pulse(0.6, ms);
  }
}

/** Sends one `head_height` per hold of both grips over `connection` (a Connection). */
export class HeightCalibration {
  constructor(connection) {
    this.connection = connection;
    this.heldSince_ms = null; // when both grips went down, null while not both held
    this.doneThisHold = false; // one calibration per hold
    this.sent_m = null; // the last height sent, for the status line
    this.armsSent = false; // an arms_forward went with the last height
  }

  /**
   * One XR frame: `time_ms` the frame's time, `headHeight_m` the viewer pose's height above the
   * floor (local-floor space), `session` the XRSession (for the grips and the buzz), `pose` the
   * `xr_pose` just sent (optional: with arms held forward in it, an `arms_forward` follows the
   * height). Returns the height sent this frame, or null.
   */
  update(time_ms, headHeight_m, session, pose = null) {
    if (!bothGripsSqueezed(session)) {
      this.heldSince_ms = null;
      this.doneThisHold = false;
      return null;
    }
    if (this.heldSince_ms === null) this.heldSince_ms = time_ms;
    if (this.doneThisHold || time_ms - this.heldSince_ms < kCalibrationHold_ms) return null;
    this.doneThisHold = true;
    const [low, high] = kHeadHeightRange_m;
    // Out of range (sitting on the floor, tracking gone wrong): the server would refuse it.
    if (!(headHeight_m >= low && headHeight_m <= high)) return null;
    if (!this.connection.send({ type: 'head_height', metres: headHeight_m })) return null;
    this.sent_m = headHeight_m;
    // After the height: the server measures the arms in it.
    this.armsSent = armsHeldForward(pose) && this.connection.send({ type: 'arms_forward' });
    buzz(session, this.armsSent ? kBuzzBody_ms : kBuzzHeight_ms);
    return headHeight_m;
  }
}
