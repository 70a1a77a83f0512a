// adviceText: the status panel's words for `stats`.advice (docs/protocol.md).
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { adviceText } from '../src/advice.js';

test('no advice, no text', () => {
  assert.equal(adviceText(undefined, true), '');
  assert.equal(adviceText({}, true), '');
  assert.equal(adviceText({ something_newer: {} }, false), '');
});

test('a calibration is advised the way this user can give it', () => {
  const headset = adviceText({ calibrate: { rig_offset: 0.0943 } }, true);
  assert.match(headset, /learnt offset 0\.094/);
  assert.match(headset, /hold both grips for a second/);
  const replay = adviceText({ calibrate: { rig_offset: 0.11 } }, false);
  assert.match(replay, /duet serve --calibration POSE\.csv/);
  assert.doesNotMatch(replay, /grips/);
});

test('an offset that is not a number is left out, not shown as NaN', () => {
  const text = adviceText({ calibrate: { rig_offset: 'x' } }, true);
  assert.doesNotMatch(text, /NaN|offset x/);
  assert.match(text, /Calibrate:/);
});

test('the VR panel wraps the advice into lines that fit', async () => {
  const { wrapLines } = await import('../src/advice_hud.js');
  const measure = (s) => s.length; // one unit a character
  assert.deepEqual(wrapLines('stand straight with both arms forward', 15, measure),
    ['stand straight', 'with both arms', 'forward']);
  assert.deepEqual(wrapLines('', 10, measure), []);
  // A word longer than the line stands on its own line, whole.
  assert.deepEqual(wrapLines('a calibration b', 5, measure), ['a', 'calibration', 'b']);
});
