// HeightCalibration: a `head_height` (docs/protocol.md) goes out once per hold of both grips, only
// after the hold has lasted a second, and only with a height the server takes. Plain objects stand
// in for the XRSession and the Connection.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import {
  HeightCalibration, armsHeldForward, bothGripsSqueezed, kBuzzBody_ms, kBuzzHeight_ms, kCalibrationHold_ms,
} from '../src/height_calibration.js';

/** A session whose left and right grips are pressed as given; pulses are counted. */
function fakeSession(left, right, pulses = []) {
  const source = (handedness, pressed) => ({
    handedness,
    gamepad: {
      buttons: [{ pressed: false }, { pressed }],
      hapticActuators: [{ pulse: (strength, ms) => pulses.push([handedness, strength, ms]) }],
    },
  });
  return { inputSources: [source('left', left), source('right', right)] };
}

function fakeConnection() {
  return { messages: [], send(msg) { this.messages.push(JSON.parse(JSON.stringify(msg))); return true; } };
}

test('both grips, not one, count as a calibration hold', () => {
  assert.equal(bothGripsSqueezed(fakeSession(true, true)), true);
  assert.equal(bothGripsSqueezed(fakeSession(true, false)), false);
  assert.equal(bothGripsSqueezed(fakeSession(false, true)), false);
  assert.equal(bothGripsSqueezed({ inputSources: [{ handedness: 'left' }, { handedness: 'right' }] }), false);
  assert.equal(bothGripsSqueezed(undefined), false);
});

test('a hold of a second sends the headset height once, with a buzz', () => {
  const connection = fakeConnection();
  const pulses = [];
  const calibration = new HeightCalibration(connection);
  const held = fakeSession(true, true, pulses);
  assert.equal(calibration.update(0, 1.62, held), null);
  assert.equal(calibration.update(kCalibrationHold_ms - 10, 1.62, held), null); // not yet
  assert.equal(calibration.update(kCalibrationHold_ms + 5, 1.63, held), 1.63);
  assert.deepEqual(connection.messages, [{ type: 'head_height', metres: 1.63 }]);
  assert.equal(pulses.length, 2); // both controllers
  assert.equal(calibration.update(kCalibrationHold_ms + 500, 1.63, held), null); // once per hold
  assert.equal(connection.messages.length, 1);
  assert.equal(calibration.sent_m, 1.63);

  // Let go and hold again: another calibration.
  assert.equal(calibration.update(3000, 1.6, fakeSession(false, true)), null);
  assert.equal(calibration.update(3100, 1.6, held), null);
  assert.equal(calibration.update(3100 + kCalibrationHold_ms, 1.6, held), 1.6);
  assert.equal(connection.messages.length, 2);
});

test('a hold broken before the second sends nothing; a height out of range is not sent', () => {
  const connection = fakeConnection();
  const calibration = new HeightCalibration(connection);
  calibration.update(0, 1.6, fakeSession(true, true));
  calibration.update(600, 1.6, fakeSession(true, false)); // one grip let go
  assert.equal(calibration.update(1200, 1.6, fakeSession(true, true)), null); // the hold restarts
  assert.equal(connection.messages.length, 0);
  const sitting = new HeightCalibration(connection);
  sitting.update(0, 0.4, fakeSession(true, true));
  assert.equal(sitting.update(kCalibrationHold_ms, 0.4, fakeSession(true, true)), null);
  assert.equal(connection.messages.length, 0);
  assert.equal(sitting.sent_m, null);
});

/** An xr_pose with the headset at 1.6 m looking along -Z (identity) and the grips where given. */
function pose(left, right, orientation = [1, 0, 0, 0]) {
  return {
    type: 'xr_pose',
    head: { position: [0, 1.6, 0], orientation },
    left: { position: left, orientation: [1, 0, 0, 0] },
    right: { position: right, orientation: [1, 0, 0, 0] },
  };
}

test('arms held forward are told from arms down, whichever way the headset looks', () => {
  assert.equal(armsHeldForward(pose([-0.18, 1.4, -0.55], [0.18, 1.4, -0.55])), true);
  assert.equal(armsHeldForward(pose([-0.25, 0.85, -0.05], [0.25, 0.85, -0.05])), false); // down
  assert.equal(armsHeldForward(pose([-0.18, 1.4, -0.55], [0.25, 0.85, -0.05])), false); // one
  assert.equal(armsHeldForward(pose([-0.18, 1.95, -0.4], [0.18, 1.95, -0.4])), false); // up
  // Turned a quarter left (about +Y): ahead is -X in the room.
  const quarter = [Math.SQRT1_2, 0, Math.SQRT1_2, 0];
  assert.equal(armsHeldForward(pose([-0.55, 1.4, 0.18], [-0.55, 1.4, -0.18], quarter)), true);
  assert.equal(armsHeldForward(pose([-0.18, 1.4, -0.55], [0.18, 1.4, -0.55], quarter)), false);
  assert.equal(armsHeldForward(null), false);
  assert.equal(armsHeldForward(pose([NaN, 1.4, -0.55], [0.18, 1.4, -0.55])), false);
});

test('a hold with the arms forward sends the height, then arms_forward; arms down only the height', () => {
  const connection = fakeConnection();
  const calibration = new HeightCalibration(connection);
  const pulses = [];
  const held = fakeSession(true, true, pulses);
  const forward = pose([-0.18, 1.4, -0.55], [0.18, 1.4, -0.55]);
  calibration.update(0, 1.6, held, forward);
  assert.equal(calibration.update(kCalibrationHold_ms, 1.6, held, forward), 1.6);
  assert.deepEqual(connection.messages, [{ type: 'head_height', metres: 1.6 }, { type: 'arms_forward' }]);
  assert.equal(calibration.armsSent, true);
  assert.deepEqual(pulses.map((p) => p[2]), [kBuzzBody_ms, kBuzzBody_ms]); // a long buzz: the body too

  calibration.update(2000, 1.6, fakeSession(false, false));
  const down = pose([-0.25, 0.85, -0.05], [0.25, 0.85, -0.05]);
  calibration.update(2100, 1.6, held, down);
  assert.equal(calibration.update(2100 + kCalibrationHold_ms, 1.6, held, down), 1.6);
  assert.deepEqual(connection.messages.slice(2), [{ type: 'head_height', metres: 1.6 }]);
  assert.equal(calibration.armsSent, false);
  assert.deepEqual(pulses.slice(2).map((p) => p[2]), [kBuzzHeight_ms, kBuzzHeight_ms]);
});
