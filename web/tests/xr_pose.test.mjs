// XRPoseSender: what goes into an xr_pose (docs/protocol.md) from a WebXR frame, and when a pose
// is held back (controllers not yet seen, the socket behind). Plain objects stand in for the
// WebXR frame and the Connection.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { XRPoseSender } from '../src/xr_pose.js';

const transform = (p, q) => ({ transform: { position: { x: p[0], y: p[1], z: p[2] }, orientation: { x: q[0], y: q[1], z: q[2], w: q[3] } } });

/** A frame whose viewer and grip poses are `poses` ({head, left, right}, missing: not tracked). */
function fakeFrame(poses, sides = ['left', 'right']) {
  const inputSources = sides.map((handedness) => ({ handedness, gripSpace: { side: handedness } }));
  return {
    session: { inputSources },
    getViewerPose: () => poses.head ?? null,
    getPose: (space) => poses[space.side] ?? null,
  };
}

function fakeConnection() {
  return {
    connected: true,
    bufferedAmount: 0,
    messages: [],
    send(msg) {
      if (!this.connected) return false;
      this.messages.push(JSON.parse(JSON.stringify(msg)));
      return true;
    },
  };
}

const kPoses = {
  head: transform([0.1, 1.6, -0.2], [0, 0.6, 0, 0.8]),
  left: transform([-0.3, 1.1, -0.4], [0.6, 0, 0, 0.8]),
  right: transform([0.3, 1.0, -0.4], [0, 0, 0.6, 0.8]),
};

test('each frame sends the head and both grips, orientations as [w, x, y, z], time in seconds', () => {
  const connection = fakeConnection();
  const sender = new XRPoseSender(connection);
  assert.ok(sender.send(1500, fakeFrame(kPoses), {}));
  assert.deepEqual(connection.messages, [{
    type: 'xr_pose',
    time_s: 1.5,
    head: { position: [0.1, 1.6, -0.2], orientation: [0.8, 0, 0.6, 0] },
    left: { position: [-0.3, 1.1, -0.4], orientation: [0.8, 0.6, 0, 0] },
    right: { position: [0.3, 1.0, -0.4], orientation: [0.8, 0, 0, 0.6] },
  }]);
  assert.equal(sender.sent, 1);
});

test('nothing is sent until both controllers were seen; a lost one keeps its last pose', () => {
  const connection = fakeConnection();
  const sender = new XRPoseSender(connection);
  assert.equal(sender.send(0, fakeFrame(kPoses, ['left']), {}), null);
  assert.equal(sender.send(10, fakeFrame({ head: kPoses.head, left: kPoses.left }), {}), null);
  assert.equal(connection.messages.length, 0);
  assert.ok(sender.send(20, fakeFrame(kPoses), {}));
  // The right controller loses tracking: its last grip pose goes on.
  assert.ok(sender.send(30, fakeFrame({ head: kPoses.head, left: kPoses.left }), {}));
  assert.deepEqual(connection.messages[1].right.position, [0.3, 1.0, -0.4]);
  // No viewer pose (the headset lost tracking): nothing.
  assert.equal(sender.send(40, fakeFrame({ left: kPoses.left, right: kPoses.right }), {}), null);
  // A new session forgets the controllers.
  sender.reset();
  assert.equal(sender.send(50, fakeFrame({ head: kPoses.head, left: kPoses.left }), {}), null);
  assert.equal(connection.messages.length, 2);
});

test('a socket that is behind or closed gets no pose, and the skip is counted', () => {
  const connection = fakeConnection();
  const sender = new XRPoseSender(connection);
  connection.bufferedAmount = 1 << 20;
  assert.equal(sender.send(0, fakeFrame(kPoses), {}), null);
  connection.bufferedAmount = 0;
  connection.connected = false;
  assert.equal(sender.send(10, fakeFrame(kPoses), {}), null);
  assert.equal(sender.skipped, 2);
  connection.connected = true;
  assert.ok(sender.send(20, fakeFrame(kPoses), {}));
  assert.equal(connection.messages.length, 1);
  assert.equal(connection.messages[0].time_s, 0.02);
});
