// A stand-in for `duet serve` that speaks docs/protocol.md: serves web/dist over HTTP and, on
// /ws, sends `hello`, 60 Hz `frame`s of two 19-joint stick dancers doing a salsa basic step,
// and `stats` each second. It plays as a file replay would (60 s, looping): `replay` messages
// pause, seek and set the speed, and `replay_state` follows each and comes with `stats`. It records every client message for tests (`received`, and
// GET /mock/received) and rejects bad ones with `error`, as the real server does.
//
//   node tests/mock-server.mjs [--port 8080] [--host 127.0.0.1] [--dist ../dist]
//
// As a module: `const mock = await startMockServer({ port: 0 })` -> { url, port, received,
// state, close() }.
import { createServer } from 'node:http';
import { readFile, stat } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { WebSocketServer } from 'ws';

const here = path.dirname(fileURLToPath(import.meta.url));
const kDefaultDist = path.resolve(here, '..', 'dist');
const kCorrections = ['align', 'contact', 'smooth', 'footlock', 'blend', 'foothold'];
const kMaxMessageBytes = 1 << 20;
const kSlowClientBytes = 256 * 1024; // drop frames for a client with this much unsent

// --- Skeleton: 19 joints (daz names, docs/skeleton-maps.md), Y up, facing +Z, left is +X. ---
// Offsets in metres from the parent, in the parent's frame, rest pose with arms down.
const kJoints = [
  ['hip', -1, [0, 0.95, 0]],
  ['abdomen', 0, [0, 0.1, 0]],
  ['chest', 1, [0, 0.2, 0]],
  ['neck', 2, [0, 0.22, 0]],
  ['head', 3, [0, 0.14, 0]],
  ['lShldr', 2, [0.18, 0.17, 0]],
  ['lForeArm', 5, [0, -0.28, 0]],
  ['lHand', 6, [0, -0.25, 0]],
  ['rShldr', 2, [-0.18, 0.17, 0]],
  ['rForeArm', 8, [0, -0.28, 0]],
  ['rHand', 9, [0, -0.25, 0]],
  ['lThigh', 0, [0.09, -0.02, 0]],
  ['lShin', 11, [0, -0.42, 0]],
  ['lFoot', 12, [0, -0.42, 0]],
  ['lFoot_End', 13, [0, -0.07, 0.13]],
  ['rThigh', 0, [-0.09, -0.02, 0]],
  ['rShin', 15, [0, -0.42, 0]],
  ['rFoot', 16, [0, -0.42, 0]],
  ['rFoot_End', 17, [0, -0.07, 0.13]],
];
const J = Object.fromEntries(kJoints.map(([name], i) => [name, i]));
export const mockSkeleton = { joints: kJoints.map(([name, parent]) => ({ name, parent })) };

// Quaternions [w, x, y, z].
const qAxis = (axis, angle) => {
  const s = Math.sin(angle / 2);
  return [Math.cos(angle / 2), axis[0] * s, axis[1] * s, axis[2] * s];
};
const qMul = (a, b) => [
  a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
  a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
  a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
  a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
];
const qRotate = (q, v) => {
  const p = qMul(qMul(q, [0, v[0], v[1], v[2]]), [q[0], -q[1], -q[2], -q[3]]);
  return [p[1], p[2], p[3]];
};
const X = [1, 0, 0];
const Y = [0, 1, 0];
const Z = [0, 0, 1];

/** World positions and rotations from local rotations and the root's world transform. */
function forwardKinematics(root_ws, root_rot_ws, local_rots) {
  const positions = [];
  const rotations = [];
  kJoints.forEach(([, parent, offset], i) => {
    const local = local_rots[i] ?? [1, 0, 0, 0];
    if (parent < 0) {
      rotations.push(qMul(root_rot_ws, local));
      positions.push(root_ws);
      return;
    }
    const o = qRotate(rotations[parent], offset);
    const p = positions[parent];
    positions.push([p[0] + o[0], p[1] + o[1], p[2] + o[2]]);
    rotations.push(qMul(rotations[parent], local));
  });
  const round = (a) => a.map((x) => Math.round(x * 1e4) / 1e4);
  return { positions: positions.map(round), rotations: rotations.map(round) };
}

/**
 * One dancer of a salsa basic: `step_phase` in radians (forward on the left at 0),
 * standing at `base` facing `yaw` (0 faces +Z). `hold`: which hand reaches for the partner.
 */
function dancerPose(step_phase, base, yaw, hold, jitter) {
  const s = Math.sin(step_phase);
  const local = kJoints.map(() => [1, 0, 0, 0]);
  const stride_m = 0.12 * s;
  // Legs: the stepping leg flexes forward (negative about +X), the knee bends back.
  local[J.lThigh] = qAxis(X, -0.45 * Math.max(0, s) + 0.15 * Math.max(0, -s));
  local[J.rThigh] = qAxis(X, 0.35 * Math.max(0, -s) - 0.1 * Math.max(0, s));
  local[J.lShin] = qAxis(X, 0.35 * Math.max(0, s));
  local[J.rShin] = qAxis(X, 0.3 * Math.max(0, -s));
  // Hips sway, chest counter-rotates a little.
  local[J.hip] = qAxis(Y, 0.15 * Math.sin(step_phase + 0.5));
  local[J.chest] = qAxis(Y, -0.12 * Math.sin(step_phase + 0.5));
  local[J.head] = qAxis(X, 0.1 * Math.sin(step_phase * 0.5));
  // The holding arm reaches forward to the partner's hand; the other swings.
  const reach = [hold === 'left' ? J.lShldr : J.rShldr, hold === 'left' ? J.lForeArm : J.rForeArm];
  const free = [hold === 'left' ? J.rShldr : J.lShldr, hold === 'left' ? J.rForeArm : J.lForeArm];
  local[reach[0]] = qMul(qAxis(X, -0.75), qAxis(Z, hold === 'left' ? -0.15 : 0.15));
  local[reach[1]] = qAxis(X, -0.55);
  local[free[0]] = qAxis(X, -0.25 * s);
  local[free[1]] = qAxis(X, -0.6);
  const yaw_q = qAxis(Y, yaw);
  const fwd = qRotate(yaw_q, [0, 0, 1]);
  const bob = 0.02 * Math.abs(s);
  const root = [
    base[0] + fwd[0] * stride_m + jitter(),
    0.95 - bob + jitter(),
    base[2] + fwd[2] * stride_m + jitter(),
  ];
  return forwardKinematics(root, yaw_q, local);
}

// --- Follower simulation -----------------------------------------------------------------
const kTakes = [
  {
    name: 'mock_salsa_a',
    frames: 720,
    contacts: [
      { user_hand: 'right', partner_hand: 'left', start: 40, end: 300 },
      { user_hand: 'left', partner_hand: 'right', start: 360, end: 520 },
      { user_hand: 'right', partner_hand: 'left', start: 560, end: 700 },
    ],
  },
  {
    name: 'mock_salsa_b',
    frames: 480,
    contacts: [{ user_hand: 'right', partner_hand: 'left', start: 0, end: 240 }],
  },
];

function percentile(sorted, p) {
  if (!sorted.length) return 0;
  return sorted[Math.min(sorted.length - 1, Math.floor(p * sorted.length))];
}

/** Checks a client message against docs/protocol.md; returns an error reason or null. */
function validate(msg) {
  if (msg === null || typeof msg !== 'object' || Array.isArray(msg)) return 'message is not a JSON object';
  switch (msg.type) {
    case 'set':
      if (!kCorrections.includes(msg.correction)) return `unknown correction '${msg.correction}'`;
      if (typeof msg.enabled !== 'boolean') return "'enabled' must be true or false";
      return null;
    case 'role':
      if (msg.role !== 'leader' && msg.role !== 'partner') return `unknown role '${msg.role}'`;
      return null;
    case 'reset':
      return null;
    case 'replay': {
      const has = (k) => k in msg;
      if (!has('paused') && !has('seek_s') && !has('speed')) return "replay: needs 'paused', 'seek_s' or 'speed'";
      if (has('paused') && typeof msg.paused !== 'boolean') return "replay: 'paused' must be true or false";
      if (has('seek_s') && !(typeof msg.seek_s === 'number' && Number.isFinite(msg.seek_s))) return "replay: 'seek_s' must be a finite number";
      if (has('speed') && !(typeof msg.speed === 'number' && msg.speed >= 0.1 && msg.speed <= 4)) return "replay: 'speed' must be a number from 0.1 to 4";
      return null;
    }
    case 'pose': {
      const num = (x) => typeof x === 'number' && Number.isFinite(x);
      if (!num(msg.time_s)) return "'time_s' must be a number";
      if (!Array.isArray(msg.root) || msg.root.length !== 3 || !msg.root.every(num)) return "'root' must be [x, y, z]";
      if (!Array.isArray(msg.rotations) || !msg.rotations.every((q) => Array.isArray(q) && q.length === 4 && q.every(num))) {
        return "'rotations' must be [[w, x, y, z], ...]";
      }
      return null;
    }
    default:
      return `unknown message type '${msg.type}'`;
  }
}

const kContentTypes = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json',
  '.svg': 'image/svg+xml',
  '.png': 'image/png',
  '.ico': 'image/x-icon',
  '.wasm': 'application/wasm',
};

export async function startMockServer({ port = 0, host = '127.0.0.1', distDir = kDefaultDist, fps = 60, log = () => {} } = {}) {
  const received = []; // every valid client message, in order, with arrival time
  const state = {
    role: 'leader',
    corrections: Object.fromEntries(kCorrections.map((c) => [c, true])),
    seq: 0,
    take: 0,
    template_frame: 0,
    since_jump_s: 0,
    jumps: 0,
    dropped: 0,
    rejected: 0,
    latencies_us: [],
    advice: null, // what `stats` advises (a test sets it), e.g. { calibrate: { rig_offset: 0.094 } }
    // The "file" the mock replays: its clock drives the dance; paused, no frames come.
    clock_s: 0,
    replay: { paused: false, speed: 1, position_s: 0, duration_s: 60, loop: true, preview: false },
  };
  const replayState = () => {
    const r = state.replay;
    return { type: 'replay_state', paused: r.paused, speed: r.speed, position_s: Math.round(r.position_s * 1000) / 1000, duration_s: r.duration_s, loop: r.loop };
  };

  const http = createServer(async (req, res) => {
    const url = new URL(req.url, 'http://mock');
    if (url.pathname === '/mock/received') {
      res.writeHead(200, { 'content-type': 'application/json', 'cache-control': 'no-store' });
      res.end(JSON.stringify(received));
      return;
    }
    const rel = decodeURIComponent(url.pathname === '/' ? '/index.html' : url.pathname);
    const file = path.resolve(distDir, '.' + rel);
    if (!file.startsWith(distDir + path.sep)) {
      res.writeHead(403).end('forbidden');
      return;
    }
    try {
      if (!(await stat(file)).isFile()) throw new Error('not a file');
      const body = await readFile(file);
      res.writeHead(200, { 'content-type': kContentTypes[path.extname(file)] ?? 'application/octet-stream' });
      res.end(body);
    } catch {
      res.writeHead(404, { 'content-type': 'text/plain' }).end(`not found: ${rel} (did you run npm run build?)`);
    }
  });

  const wss = new WebSocketServer({ noServer: true, maxPayload: 4 * kMaxMessageBytes }); // bigger still closes the socket
  http.on('upgrade', (req, socket, head) => {
    if (new URL(req.url, 'http://mock').pathname !== '/ws') {
      socket.destroy();
      return;
    }
    wss.handleUpgrade(req, socket, head, (ws) => wss.emit('connection', ws, req));
  });

  const hello = () => ({
    type: 'hello',
    version: 1,
    role: state.role,
    fps,
    user_skeleton: mockSkeleton,
    partner_skeleton: mockSkeleton,
    takes: kTakes,
    corrections: { ...state.corrections },
  });

  const sendJson = (ws, msg) => {
    if (ws.readyState === ws.OPEN) ws.send(JSON.stringify(msg));
  };

  wss.on('connection', (ws) => {
    log('client connected');
    sendJson(ws, hello());
    ws.on('message', (data, is_binary) => {
      const reject = (reason) => {
        state.rejected += 1;
        sendJson(ws, { type: 'error', reason });
      };
      if (is_binary) return reject('binary messages are not accepted');
      if (data.length > kMaxMessageBytes) return reject('message larger than 1 MiB');
      let msg;
      try {
        msg = JSON.parse(data.toString('utf8'));
      } catch (err) {
        return reject(`not JSON: ${err.message}`);
      }
      const bad = validate(msg);
      if (bad) return reject(bad);
      received.push({ ...msg, received_ms: Date.now() });
      log('received', JSON.stringify(msg));
      if (msg.type === 'set') {
        state.corrections[msg.correction] = msg.enabled;
      } else if (msg.type === 'role') {
        // The follower restarts; the mock tells every client the new roles with a new hello.
        state.role = msg.role;
        state.template_frame = 0;
        for (const client of wss.clients) sendJson(client, hello());
      } else if (msg.type === 'replay') {
        const r = state.replay;
        if ('speed' in msg) r.speed = msg.speed;
        if ('seek_s' in msg) {
          r.position_s = Math.min(Math.max(msg.seek_s, 0), r.duration_s - 1 / fps);
          r.preview = r.paused; // like duet serve: a seek while paused shows that frame once
        }
        if ('paused' in msg) r.paused = msg.paused;
        for (const client of wss.clients) sendJson(client, replayState());
      } else if (msg.type === 'reset') {
        state.template_frame = 0;
        state.take = 0;
        for (const c of kCorrections) state.corrections[c] = true;
      }
    });
  });

  // 60 Hz frames. Leader at z = -0.45 facing +Z, partner at z = +0.45 facing -Z; the couple
  // turns back and forth a little. The leader holds with the right hand, the partner the left.
  const t0 = performance.now();
  let last_s = 0;
  const tick = () => {
    const wall_s = (performance.now() - t0) / 1000;
    const wall_dt_s = wall_s - last_s;
    last_s = wall_s;
    const r = state.replay;
    if (r.paused && !r.preview) return;
    // The dance and the follower run on the replayed file's clock.
    const dt_s = r.paused ? 0 : wall_dt_s * r.speed;
    r.preview = false;
    r.position_s = (r.position_s + dt_s) % r.duration_s;
    const t_s = r.position_s;
    state.clock_s += Math.max(dt_s, 1 / fps); // time_s goes on across seeks, still while paused
    state.seq += 1;

    // Follower: advance one template frame per input frame, jump every ~4 s.
    const take = kTakes[state.take];
    let jumped = false;
    state.template_frame += 1;
    state.since_jump_s += dt_s;
    if (state.template_frame >= take.frames || state.since_jump_s > 4) {
      state.jumps += 1;
      state.since_jump_s = 0;
      jumped = true;
      if (state.jumps % 3 === 0) state.take = (state.take + 1) % kTakes.length;
      const frames = kTakes[state.take].frames;
      state.template_frame = (state.template_frame + 97 * state.jumps) % frames;
    }
    // Reaches 1 for about a second in every seven, so the timeline's top edge gets drawn on.
    const confidence = jumped ? 0.45 : Math.min(1, 0.85 + 0.2 * Math.sin(t_s * 0.9));
    const f = state.template_frame;
    const in_contact = (hand) => kTakes[state.take].contacts.some((c) => c.user_hand === hand && f >= c.start && f < c.end);

    const build_start = process.hrtime.bigint();
    const couple_yaw = 0.5 * Math.sin(t_s * 0.25);
    const turn = (v) => qRotate(qAxis(Y, couple_yaw), v);
    const phase = (2 * Math.PI * t_s) / 2.0;
    const jitter = state.corrections.smooth ? () => 0 : () => (Math.random() - 0.5) * 0.03;
    const leader = dancerPose(phase, turn([0, 0, -0.45]), couple_yaw, 'right', () => 0);
    const follower = dancerPose(phase + Math.PI, turn([0, 0, 0.45]), couple_yaw + Math.PI, 'left', jitter);
    const user_is_leader = state.role === 'leader';
    const frame = {
      type: 'frame',
      seq: state.seq,
      time_s: Math.round(state.clock_s * 1000) / 1000,
      follower: {
        take: state.take,
        template_frame: f,
        confidence: Math.round(confidence * 100) / 100,
        jumped,
        lost: false,
        in_pause: false,
      },
      user: user_is_leader ? leader : follower,
      partner: user_is_leader ? follower : leader,
      corrections: { ...state.corrections },
      contact: { left: in_contact('left'), right: in_contact('right') },
      latency_us: 0,
    };
    frame.latency_us = Number((process.hrtime.bigint() - build_start) / 1000n);
    state.latencies_us.push(frame.latency_us);
    const text = JSON.stringify(frame);
    for (const ws of wss.clients) {
      if (ws.readyState !== ws.OPEN) continue;
      if (ws.bufferedAmount > kSlowClientBytes) {
        state.dropped += 1;
        continue;
      }
      ws.send(text);
    }
  };
  const frame_timer = setInterval(tick, 1000 / fps);

  const stats_timer = setInterval(() => {
    const sorted = state.latencies_us.splice(0).sort((a, b) => a - b);
    const stats = {
      type: 'stats',
      frames: state.seq,
      clients: wss.clients.size,
      dropped: state.dropped,
      rejected: state.rejected,
      latency_us: { p50: percentile(sorted, 0.5), p99: percentile(sorted, 0.99), max: sorted.at(-1) ?? 0 },
      ...(state.advice ? { advice: state.advice } : {}),
    };
    for (const ws of wss.clients) {
      sendJson(ws, stats);
      sendJson(ws, replayState());
    }
  }, 1000);

  await new Promise((resolve, reject) => {
    http.once('error', reject);
    http.listen(port, host, resolve);
  });
  const actual_port = http.address().port;
  return {
    url: `http://${host}:${actual_port}/`,
    port: actual_port,
    received,
    state,
    /** Cuts every client off (the viewer should reconnect). */
    dropClients: () => {
      for (const ws of wss.clients) ws.terminate();
    },
    close: () =>
      new Promise((resolve) => {
        clearInterval(frame_timer);
        clearInterval(stats_timer);
        for (const ws of wss.clients) ws.terminate();
        wss.close();
        http.close(() => resolve());
        http.closeAllConnections?.();
      }),
  };
}

// Run directly: serve until interrupted.
if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const arg = (name, fallback) => {
    const i = process.argv.indexOf(`--${name}`);
    return i > 0 && i + 1 < process.argv.length ? process.argv[i + 1] : fallback;
  };
  const mock = await startMockServer({
    port: Number(arg('port', 8080)),
    host: arg('host', '127.0.0.1'),
    distDir: path.resolve(arg('dist', kDefaultDist)),
    log: (...a) => console.log(new Date().toISOString(), ...a),
  });
  console.log(`mock duet server: ${mock.url} (WebSocket ${mock.url.replace('http', 'ws')}ws)`);
  const stop = async () => {
    await mock.close();
    process.exit(0);
  };
  process.on('SIGINT', stop);
  process.on('SIGTERM', stop);
}
