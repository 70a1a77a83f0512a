// The headset source's input (docs/protocol.md, `xr_pose`): each XR frame, the viewer pose and
// both controllers' grip poses go to `duet serve --source xr`, which follows them.

// Past this many unsent bytes (about 50 poses) the link is behind: skip a pose rather than
// queue it, so the server always gets the newest one and the browser never queues without bound.
const kMaxBufferedBytes = 16 * 1024;

function emptyPoint() {
  return { position: [0, 0, 0], orientation: [1, 0, 0, 0] };
}

/** Copies an XRRigidTransform into a point of the message ([w, x, y, z] orientation). */
function copyTransform(transform, point) {
  const p = transform.position;
  const q = transform.orientation;
  point.position[0] = p.x;
  point.position[1] = p.y;
  point.position[2] = p.z;
  point.orientation[0] = q.w;
  point.orientation[1] = q.x;
  point.orientation[2] = q.y;
  point.orientation[3] = q.z;
}

/**
 * Sends one `xr_pose` per XR frame over `connection` (a Connection). One message object is
 * reused. A controller that loses tracking is sent at its last pose; nothing is sent until
 * the headset and both controllers have been seen once.
 */
export class XRPoseSender {
  constructor(connection) {
    this.connection = connection;
    this.message = { type: 'xr_pose', time_s: 0, head: emptyPoint(), left: emptyPoint(), right: emptyPoint() };
    this.seen = { left: false, right: false };
    this.sent = 0;
    this.skipped = 0; // poses not sent because the socket was behind (or closed)
  }

  /** Forgets the controllers (a new session may have other ones). */
  reset() {
    this.seen.left = false;
    this.seen.right = false;
  }

  /**
   * Reads the poses of `frame` (an XRFrame) in `refSpace` (the session's 'local-floor' space)
   * at `time_ms` (the frame's time) and sends them. Returns the message sent, or null.
   */
  send(time_ms, frame, refSpace) {
    if (!refSpace) return null;
    const viewer = frame.getViewerPose(refSpace);
    if (!viewer) return null; // tracking lost: the follower waits rather than guess
    copyTransform(viewer.transform, this.message.head);
    for (const source of frame.session.inputSources) {
      const side = source.handedness;
      if ((side !== 'left' && side !== 'right') || !source.gripSpace) continue;
      const grip = frame.getPose(source.gripSpace, refSpace);
      if (!grip) continue;
      copyTransform(grip.transform, this.message[side]);
      this.seen[side] = true;
    }
    if (!this.seen.left || !this.seen.right) return null;
    this.message.time_s = time_ms / 1000;
    if (this.connection.bufferedAmount > kMaxBufferedBytes || !this.connection.send(this.message)) {
      this.skipped += 1;
      return null;
    }
    this.sent += 1;
    return this.message;
  }
}
