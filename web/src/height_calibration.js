// A height calibration in VR (docs/protocol.md, `head_height`): standing straight, the user
// holds both controllers' grip buttons for a second, and the headset's height goes to the server,
// which then knows the user's size from the first step instead of learning it from the highest
// the head has been (a dance that starts low fools that for its first seconds).

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

/** A short buzz in both controllers: the calibration was sent. Headsets without haptics: none. */
function buzz(session) {
  for (const source of session?.inputSources ?? []) {
    const actuator = source.gamepad?.hapticActuators?.[0];
    if (typeof actuator?.pulse === 'function') actuator.pulse(0.6, 120);
  }
}

/** Sends one `head_height` per hold of both grips over `connection` (a Connection). */
export class HeightCalibration {
  constructor(connection) {
    this.connection = connection;
    this.heldSince_ms = null; // when both grips went down, null while not both held
    this.doneThisHold = false; // one calibration per hold
    this.sent_m = null; // the last height sent, for the status line
  }

  /**
   * One XR frame: `time_ms` the frame's time, `headHeight_m` the viewer pose's height above the
   * floor (local-floor space), `session` the XRSession (for the grips and the buzz). Returns the
   * height sent this frame, or null.
   */
  update(time_ms, headHeight_m, session) {
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
    buzz(session);
    return headHeight_m;
  }
}
