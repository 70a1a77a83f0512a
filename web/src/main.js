// Duet viewer: shows the user and the virtual partner streamed by `duet serve`
// (docs/protocol.md), the follower's timeline, and the corrections' switches.
//
// Data flow: socket message -> state (latest frame kept, never queued) -> render loop applies
// the latest frame once per displayed frame -> three.js scene, timeline canvas, status line.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { Connection, defaultSocketUrl } from './connection.js';
import { StickFigure, kRoleColors } from './dancers.js';
import { Timeline } from './timeline.js';
import { VRSession, installXREmulator, placeRigAtHead } from './xr.js';
import { XRPoseSender } from './xr_pose.js';
import { HeightCalibration } from './height_calibration.js';
import { adviceText } from './advice.js';
import { AdviceHud } from './advice_hud.js';

const kCorrections = ['align', 'contact', 'smooth', 'footlock', 'blend', 'foothold'];
const kPendingToggle_s = 1.5; // how long a clicked switch waits for the server to confirm it
const kOrbitFollowHalfLife_s = 0.4; // the orbit target trails the couple's midpoint
const kFirstPersonFov = 70;
const kSeekInterval_ms = 100; // while dragging the replay slider, at most this often a seek

const params = new URLSearchParams(location.search);

/** A floor grid of `size` metres with `divisions` cells a side, lines along X and along Z.
 *  Unlike THREE.GridHelper, every line is cut into one segment per cell: a line that runs from
 *  behind the camera to the horizon was dropped whole by some WebGL implementations (SwiftShader
 *  showed the lines along one axis only); short segments are clipped one by one. */
function makeFloorGrid(size, divisions, centreColor, lineColor) {
  const step = size / divisions;
  const half = size / 2;
  const positions = [];
  const colors = [];
  const centre = new THREE.Color(centreColor);
  const line = new THREE.Color(lineColor);
  const counts = { alongX: 0, alongZ: 0 };
  for (let i = 0; i <= divisions; ++i) {
    const k = -half + i * step;
    const color = i === divisions / 2 ? centre : line;
    for (let c = 0; c < divisions; ++c) {
      const a = -half + c * step;
      positions.push(a, 0, k, a + step, 0, k); // along X at z = k
      positions.push(k, 0, a, k, 0, a + step); // along Z at x = k
      for (let v = 0; v < 4; ++v) colors.push(color.r, color.g, color.b);
      counts.alongX += 1;
      counts.alongZ += 1;
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
  const grid = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true, toneMapped: false }));
  grid.userData.segments = counts;
  return grid;
}

async function main() {
  // The emulated headset must be navigator.xr before three.js looks for one.
  let xr_device = null;
  if (params.get('xr-emulate') === '1') {
    try {
      xr_device = await installXREmulator();
    } catch (err) {
      console.error('duet viewer: cannot install the WebXR emulator', err);
    }
  }

  const el = (id) => document.getElementById(id);
  const ui = {
    conn: el('status-conn'),
    fps: el('status-fps'),
    latency: el('status-latency'),
    error: el('status-error'),
    advice: el('status-advice'),
    role: el('role'),
    reset: el('reset'),
    view: el('view'),
    vr: el('vr'),
    toggles: Object.fromEntries(kCorrections.map((c) => [c, el(`corr-${c}`)])),
    replay: el('replay'),
    replayPlay: el('replay-play'),
    replaySeek: el('replay-seek'),
    replayTime: el('replay-time'),
    replaySpeed: el('replay-speed'),
  };

  // --- Scene -------------------------------------------------------------------------------
  const renderer = new THREE.WebGLRenderer({ antialias: true });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.xr.enabled = true;
  el('viewport').appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x15171c);
  scene.add(new THREE.HemisphereLight(0xe8eeff, 0x30323a, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(3, 6, 2);
  scene.add(sun);
  const grid = makeFloorGrid(20, 40, 0x5a6070, 0x2c3038);
  scene.add(grid);

  // The camera hangs from a rig: identity on the desktop, at the user's head in VR.
  const rig = new THREE.Group();
  scene.add(rig);
  const camera = new THREE.PerspectiveCamera(50, window.innerWidth / window.innerHeight, 0.05, 100);
  camera.position.set(3.4, 1.9, 1.4); // side-on to a couple that faces along Z
  rig.add(camera);
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.set(0, 1.0, 0);
  controls.enableDamping = true;
  controls.update();

  // Lines between held hands while frame.contact says so.
  const contact_lines = {};
  for (const side of ['left', 'right']) {
    const geo = new THREE.BufferGeometry().setAttribute(
      'position',
      new THREE.BufferAttribute(new Float32Array(6), 3),
    );
    const line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: 0xffe08a }));
    line.visible = false;
    line.frustumCulled = false;
    scene.add(line);
    contact_lines[side] = line;
  }

  const timeline = new Timeline(el('timeline'));

  // --- State -------------------------------------------------------------------------------
  const state = {
    hello: null,
    role: 'leader', // the dance role of the user, from hello or the role switch
    user: null, // StickFigure
    partner: null,
    framesReceived: 0,
    lastFrame: null,
    pendingFrame: null, // newest frame not yet shown
    lastStats: null,
    errors: [], // `error` replies and malformed messages, newest last
    seqGaps: 0, // frames the server dropped for us (gaps in seq)
    renderCount: 0,
    cameraMode: 'orbit', // 'orbit' | 'first-person' | 'vr'
    frozen: false, // test hook: stop applying frames
    framed: false, // the orbit camera was placed side-on to the couple
    pending: {}, // correction -> {enabled, until_ms} after a click
  };
  const rates = { renders: 0, frames: 0, since_ms: performance.now(), fps: 0, frameRate: 0 };
  // A file replay's state from `replay_state` (null: the source is not a replay), when it came,
  // and the slider while the user drags it.
  const replay = { state: null, received_ms: 0, dragging: false, last_seek_ms: 0, states: 0 };

  function otherRole(role) {
    return role === 'partner' ? 'leader' : 'partner';
  }

  function applyRoleColors() {
    state.user?.setColor(kRoleColors[state.role]);
    state.partner?.setColor(kRoleColors[otherRole(state.role)]);
    ui.role.value = state.role;
  }

  function showError(text) {
    state.errors.push(text);
    if (state.errors.length > 50) state.errors.shift();
    ui.error.textContent = text;
    ui.error.hidden = false;
    clearTimeout(showError.timer);
    showError.timer = setTimeout(() => (ui.error.hidden = true), 6000);
  }

  // --- Messages ----------------------------------------------------------------------------
  function onHello(msg) {
    if (msg.version !== 1) showError(`server speaks protocol version ${msg.version}, viewer knows 1`);
    state.user?.dispose();
    state.partner?.dispose();
    state.hello = msg;
    state.role = msg.role === 'partner' ? 'partner' : 'leader';
    state.user = new StickFigure(msg.user_skeleton, kRoleColors[state.role]);
    state.user.setDeviceOffsets(msg.device_offsets);
    state.partner = new StickFigure(msg.partner_skeleton, kRoleColors[otherRole(state.role)]);
    scene.add(state.user.group, state.partner.group);
    state.user.setHeadHidden(state.cameraMode !== 'orbit');
    state.pendingFrame = null;
    state.lastSeq = null;
    timeline.setTakes(msg.takes, msg.fps);
    applyRoleColors();
    reflectCorrections(msg.corrections);
    for (const input of [ui.role, ui.reset, ...Object.values(ui.toggles)]) input.disabled = false;
  }

  function onFrame(msg) {
    if (!state.hello) return; // a frame before hello has no skeleton to pose
    state.framesReceived += 1;
    rates.frames += 1;
    if (Number.isInteger(msg.seq)) {
      if (Number.isInteger(state.lastSeq) && msg.seq > state.lastSeq + 1) {
        state.seqGaps += msg.seq - state.lastSeq - 1;
      }
      state.lastSeq = msg.seq;
    }
    state.lastFrame = msg;
    state.pendingFrame = msg;
    if (!state.frozen) timeline.push(msg.follower); // frozen: the timeline holds still too
    reflectCorrections(msg.corrections);
  }

  /** Shows the server's corrections, except a switch the user just clicked and the server
   *  has not confirmed yet (so it does not flicker back for a frame or two). */
  function reflectCorrections(corrections) {
    if (!corrections || typeof corrections !== 'object') return;
    const now = performance.now();
    for (const name of kCorrections) {
      if (typeof corrections[name] !== 'boolean') continue;
      const pending = state.pending[name];
      if (pending) {
        if (corrections[name] === pending.enabled || now > pending.until_ms) delete state.pending[name];
        else continue;
      }
      ui.toggles[name].checked = corrections[name];
    }
  }

  function onMessage(msg) {
    switch (msg.type) {
      case 'hello':
        onHello(msg);
        break;
      case 'frame':
        onFrame(msg);
        break;
      case 'stats':
        state.lastStats = msg;
        break;
      case 'error':
        showError(`server: ${msg.reason ?? 'error'}`);
        break;
      case 'replay_state':
        onReplayState(msg);
        break;
      default:
        break; // newer servers may send more; ignore what we do not know
    }
  }

  // --- Replay (pause, seek, speed of a file the server plays) ---------------------------------
  function onReplayState(msg) {
    const duration = Number(msg.duration_s);
    if (!(duration > 0)) return;
    replay.state = {
      paused: !!msg.paused,
      speed: Number(msg.speed) || 1,
      position_s: Number(msg.position_s) || 0,
      duration_s: duration,
      loop: !!msg.loop,
    };
    replay.received_ms = performance.now();
    replay.states += 1;
    ui.replay.hidden = false;
    ui.replaySeek.max = String(duration);
    const speed = String(replay.state.speed);
    if (![...ui.replaySpeed.options].some((o) => o.value === speed)) {
      ui.replaySpeed.add(new Option(`${speed}x`, speed)); // a speed from the command line
    }
    ui.replaySpeed.value = speed;
    ui.replayPlay.textContent = replay.state.paused ? 'Play' : 'Pause';
    updateReplayPosition();
  }

  /** Where the file is now: the last state moved on by the time since, at its speed. */
  function replayPosition() {
    const s = replay.state;
    if (!s) return 0;
    let p = s.position_s;
    if (!s.paused) p += ((performance.now() - replay.received_ms) / 1000) * s.speed;
    return s.loop ? p % s.duration_s : Math.min(p, s.duration_s);
  }

  function updateReplayPosition() {
    if (!replay.state) return;
    const p = replay.dragging ? Number(ui.replaySeek.value) : replayPosition();
    if (!replay.dragging) ui.replaySeek.value = String(p);
    ui.replayTime.textContent = `${p.toFixed(1)} / ${replay.state.duration_s.toFixed(1)} s`;
  }

  /** Sends a `replay` control and shows its effect at once; the server's replay_state confirms. */
  function sendReplay(fields) {
    if (!replay.state || !connection.send({ type: 'replay', ...fields })) return false;
    const s = replay.state;
    s.position_s = replayPosition();
    replay.received_ms = performance.now();
    if ('paused' in fields) s.paused = fields.paused;
    if ('speed' in fields) s.speed = fields.speed;
    if ('seek_s' in fields) s.position_s = fields.seek_s;
    ui.replayPlay.textContent = s.paused ? 'Play' : 'Pause';
    return true;
  }

  const connection = new Connection(defaultSocketUrl(location), {
    onMessage,
    onOpen: () => updateStatus(),
    onClose: () => {
      for (const input of [ui.role, ui.reset, ...Object.values(ui.toggles)]) input.disabled = true;
      // The next server may not play a file; its replay_state shows the controls again.
      replay.state = null;
      ui.replay.hidden = true;
      updateStatus();
    },
    onBadMessage: (_text, reason) => showError(`bad message: ${reason}`),
  });
  // In VR on a headset-source server, the headset and controllers are the user's input.
  const xr_sender = new XRPoseSender(connection);
  // Standing straight, both grips held for a second: the headset's height (head_height).
  const height_calibration = new HeightCalibration(connection);
  let xr_frame_hook = null; // test hook: (time_ms, message sent or null) after each XR frame
  const headsetIsSource = () => state.hello?.source_kind === 'xr';

  // --- Controls ----------------------------------------------------------------------------
  for (const name of kCorrections) {
    ui.toggles[name].addEventListener('change', (event) => {
      const enabled = event.target.checked;
      if (connection.send({ type: 'set', correction: name, enabled })) {
        state.pending[name] = { enabled, until_ms: performance.now() + kPendingToggle_s * 1000 };
      } else {
        event.target.checked = !enabled;
      }
    });
  }

  ui.role.addEventListener('change', () => {
    const role = ui.role.value === 'partner' ? 'partner' : 'leader';
    if (!connection.send({ type: 'role', role })) {
      ui.role.value = state.role;
      return;
    }
    // The user now dances `role`; colours follow the dance role. A new hello, if the server
    // sends one, overrides this.
    state.role = role;
    applyRoleColors();
    timeline.clear();
  });

  ui.replayPlay.addEventListener('click', () => {
    if (replay.state) sendReplay({ paused: !replay.state.paused });
  });
  ui.replaySeek.addEventListener('input', () => {
    // Scrubbing: seek while dragging, but not on every pixel.
    replay.dragging = true;
    const now = performance.now();
    if (now - replay.last_seek_ms >= kSeekInterval_ms) {
      replay.last_seek_ms = now;
      sendReplay({ seek_s: Number(ui.replaySeek.value) });
    }
    updateReplayPosition();
  });
  ui.replaySeek.addEventListener('change', () => {
    replay.dragging = false;
    replay.last_seek_ms = performance.now();
    sendReplay({ seek_s: Number(ui.replaySeek.value) });
    updateReplayPosition();
  });
  ui.replaySpeed.addEventListener('change', () => {
    const speed = Number(ui.replaySpeed.value);
    if (!sendReplay({ speed })) ui.replaySpeed.value = String(replay.state?.speed ?? 1);
  });

  ui.reset.addEventListener('click', () => {
    if (connection.send({ type: 'reset' })) timeline.clear();
  });

  const orbit_saved = { position: new THREE.Vector3(), target: new THREE.Vector3(), fov: camera.fov };

  function setCameraMode(mode) {
    if (mode === state.cameraMode) return;
    if (state.cameraMode === 'orbit') {
      orbit_saved.position.copy(camera.position);
      orbit_saved.target.copy(controls.target);
      orbit_saved.fov = camera.fov;
    }
    state.cameraMode = mode;
    controls.enabled = mode === 'orbit';
    ui.view.disabled = mode === 'vr';
    state.user?.setHeadHidden(mode !== 'orbit');
    if (mode === 'orbit') {
      rig.position.set(0, 0, 0);
      rig.quaternion.identity();
      camera.position.copy(orbit_saved.position);
      controls.target.copy(orbit_saved.target);
      camera.fov = orbit_saved.fov;
      camera.updateProjectionMatrix();
      controls.update();
    } else if (mode === 'first-person') {
      camera.fov = kFirstPersonFov;
      camera.updateProjectionMatrix();
    }
    ui.view.textContent = mode === 'first-person' ? 'Orbit view' : 'First-person view';
  }

  ui.view.addEventListener('click', () => {
    if (state.cameraMode === 'vr') return;
    setCameraMode(state.cameraMode === 'orbit' ? 'first-person' : 'orbit');
  });

  let mode_before_vr = 'orbit';
  const vr = new VRSession(renderer, ui.vr, {
    onStart: () => {
      xr_sender.reset();
      mode_before_vr = state.cameraMode;
      setCameraMode('vr');
    },
    onEnd: () => {
      setCameraMode(mode_before_vr);
      onResize();
    },
  });
  vr.probe();

  function onResize() {
    if (renderer.xr.isPresenting) return;
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(window.innerWidth, window.innerHeight);
  }
  window.addEventListener('resize', onResize);

  // --- Per displayed frame -----------------------------------------------------------------
  const tmp = { head: new THREE.Vector3(), facing: new THREE.Vector3(), mid: new THREE.Vector3() };

  function applyFrame(frame) {
    const first = !state.user.posed;
    state.user.applyPose(frame.user);
    state.partner.applyPose(frame.partner);
    updateContactLines(frame);
    if (first && !state.framed && state.cameraMode === 'orbit') {
      viewSideOn(); // once per page; later hellos (reconnects, role switches) keep the view
      state.framed = true;
    }
  }

  /** Puts the orbit camera side-on to the couple, far enough to see both whole. */
  function viewSideOn() {
    if (!state.user?.posed || !state.partner?.posed) return;
    const a = state.user.headPosition(new THREE.Vector3());
    const b = state.partner.headPosition(new THREE.Vector3());
    const across = new THREE.Vector3().subVectors(b, a).setY(0);
    const separation = across.length();
    const side = separation > 1e-3
      ? new THREE.Vector3().crossVectors(across, new THREE.Vector3(0, 1, 0)).normalize()
      : state.user.facing(new THREE.Vector3()).applyAxisAngle(new THREE.Vector3(0, 1, 0), Math.PI / 2);
    controls.target.addVectors(a, b).multiplyScalar(0.5).setY(1.0);
    camera.position.copy(controls.target).addScaledVector(side, Math.max(3.6, 2 * separation)).setY(1.9);
    controls.update();
  }

  function updateContactLines(frame) {
    for (const side of ['left', 'right']) {
      const line = contact_lines[side];
      line.visible = false;
      if (!frame.contact?.[side]) continue;
      const user_hand = state.user.roles[`${side}_wrist`];
      const partner_side = partnerHandFor(side, frame.follower);
      const partner_hand = state.partner.roles[`${partner_side}_wrist`];
      if (user_hand < 0 || partner_hand < 0) continue;
      const pos = line.geometry.attributes.position;
      pos.setXYZ(0, ...state.user.positions_ws[user_hand].toArray());
      pos.setXYZ(1, ...state.partner.positions_ws[partner_hand].toArray());
      pos.needsUpdate = true;
      line.visible = true;
    }
  }

  /** The partner's hand that holds the user's `side` hand: from the take's contact interval
   *  around the current frame, else the mirror hand (dancers face each other). */
  function partnerHandFor(side, follower) {
    const take = state.hello?.takes?.[follower?.take];
    const f = follower?.template_frame;
    for (const c of take?.contacts ?? []) {
      if (c.user_hand === side && f >= c.start && f < c.end && (c.partner_hand === 'left' || c.partner_hand === 'right')) {
        return c.partner_hand;
      }
    }
    return side === 'left' ? 'right' : 'left';
  }

  function updateCamera(dt_s) {
    const user = state.user;
    if (state.cameraMode === 'vr') {
      if (headsetIsSource()) {
        // The room is the world: the server places the partner in the headset's own
        // 'local-floor' space, in metres, so the rig stays at the origin.
        rig.position.set(0, 0, 0);
        rig.quaternion.identity();
      } else if (user?.posed) {
        placeRigAtHead(rig, user.headPosition(tmp.head), user.facing(tmp.facing));
      }
      return;
    }
    if (state.cameraMode === 'first-person') {
      if (!user?.posed) return;
      const head = user.headPosition(tmp.head);
      const facing = user.facing(tmp.facing);
      camera.position.copy(head).addScaledVector(facing, 0.06);
      // Look along the facing, tilted a little down so the partner's torso is in view.
      tmp.mid.copy(camera.position).add(facing);
      tmp.mid.y -= 0.25;
      camera.lookAt(tmp.mid);
      return;
    }
    // Orbit: the target trails the couple, the camera keeps its offset from it.
    if (user?.posed && state.partner?.posed && !state.frozen) {
      tmp.mid.addVectors(user.headPosition(tmp.head), state.partner.headPosition(tmp.facing)).multiplyScalar(0.5);
      tmp.mid.y = 1.0;
      const k = 1 - Math.pow(0.5, dt_s / kOrbitFollowHalfLife_s);
      tmp.mid.sub(controls.target).multiplyScalar(k);
      controls.target.add(tmp.mid);
      camera.position.add(tmp.mid);
    }
    controls.update();
  }

  function updateStatus() {
    ui.conn.textContent = connection.connected ? 'connected' : 'disconnected (reconnecting)';
    ui.conn.className = connection.connected ? 'connected' : 'disconnected';
    ui.fps.textContent = `${rates.fps.toFixed(0)} fps, ${rates.frameRate.toFixed(0)} frames/s` +
      (state.seqGaps ? `, ${state.seqGaps} skipped` : '');
    const s = state.lastStats;
    const ms = (us) => (Number(us) / 1000).toFixed(2);
    const frame_us = state.lastFrame?.latency_us;
    const parts = [];
    if (s?.latency_us) parts.push(`latency p50/p99/max ${ms(s.latency_us.p50)}/${ms(s.latency_us.p99)}/${ms(s.latency_us.max)} ms`);
    else if (frame_us !== undefined) parts.push(`latency ${ms(frame_us)} ms`);
    if (s) parts.push(`${s.clients} clients, ${s.dropped} dropped`);
    ui.latency.textContent = parts.join(', ');
    showAdvice(s?.advice);
  }

  // What the server advises (`stats`.advice): a body calibration, in words (advice.js), in the
  // status panel and, in VR, on a panel below the line of sight (advice_hud.js).
  const advice_hud = new AdviceHud(camera);
  function showAdvice(advice) {
    const text = adviceText(advice, headsetIsSource());
    if (ui.advice.textContent !== text) ui.advice.textContent = text;
    ui.advice.hidden = !text;
    advice_hud.show(text, renderer.xr.isPresenting);
  }

  let last_ms = performance.now();
  renderer.setAnimationLoop((time_ms, xr_frame) => {
    if (xr_frame && headsetIsSource() && renderer.xr.isPresenting) {
      const sent = xr_sender.send(time_ms, xr_frame, renderer.xr.getReferenceSpace());
      if (sent) height_calibration.update(time_ms, sent.head.position[1], xr_frame.session, sent);
      xr_frame_hook?.(time_ms, sent);
    }
    const now = performance.now();
    const dt_s = Math.min(0.1, (now - last_ms) / 1000);
    last_ms = now;
    if (state.pendingFrame && !state.frozen && state.user) {
      applyFrame(state.pendingFrame);
      state.pendingFrame = null;
    }
    updateCamera(dt_s);
    renderer.render(scene, camera);
    state.renderCount += 1;
    rates.renders += 1;
    if (!renderer.xr.isPresenting) {
      timeline.draw();
      updateReplayPosition();
    }
    if (now - rates.since_ms >= 1000) {
      const span_s = (now - rates.since_ms) / 1000;
      rates.fps = rates.renders / span_s;
      rates.frameRate = rates.frames / span_s;
      rates.renders = 0;
      rates.frames = 0;
      rates.since_ms = now;
      updateStatus();
    }
  });

  // --- Test hook: observe state without scraping pixels --------------------------------------
  const project = (figure) => {
    if (!figure?.posed) return [];
    const rect = renderer.domElement.getBoundingClientRect();
    return figure.positions_ws.map((p) => {
      const v = p.clone().project(camera);
      return { x: rect.left + ((v.x + 1) / 2) * rect.width, y: rect.top + ((1 - v.y) / 2) * rect.height, z: v.z };
    });
  };
  window.duetViewer = {
    get framesReceived() { return state.framesReceived; },
    get lastFrame() { return state.lastFrame; },
    get connected() { return connection.connected; },
    get renderCount() { return state.renderCount; },
    get xrPresenting() { return renderer.xr.isPresenting; },
    get hello() { return state.hello; },
    get role() { return state.role; },
    get lastStats() { return state.lastStats; },
    /** The advice's panel in VR: its text and whether it is shown. */
    get adviceHud() { return { text: advice_hud.text, visible: advice_hud.visible }; },
    get errors() { return state.errors.slice(); },
    get seqGaps() { return state.seqGaps; },
    get cameraMode() { return state.cameraMode; },
    get xrEmulated() { return xr_device !== null; },
    /** The emulated headset (iwer's XRDevice) with `?xr-emulate=1`, else null. */
    get xrDevice() { return xr_device; },
    /** xr_pose messages sent and skipped (socket behind) in VR on a headset source. */
    get xrPoses() { return { sent: xr_sender.sent, skipped: xr_sender.skipped }; },
    /** The last height calibration sent (head_height, metres), null before any. */
    get headHeightSent() { return height_calibration.sent_m; },
    get armsForwardSent() { return height_calibration.armsSent; },
    /** Calls `fn(time_ms, sent)` after each XR frame on a headset source (null: stop). */
    setXRFrameHook(fn) { xr_frame_hook = typeof fn === 'function' ? fn : null; },
    /** In VR, the partner as the headset's left eye sees it: its hips in normalized device
     *  coordinates, the hips' floor distance from the eye, the partner's head height, how
     *  squarely it faces the eye (cosine), and which of the user's points are drawn. Null outside VR or before a frame. */
    xrView() {
      if (!renderer.xr.isPresenting || !state.partner?.posed) return null;
      const eye = renderer.xr.getCamera().cameras[0];
      if (!eye) return null;
      const hips = state.partner.positions_ws[Math.max(0, state.partner.roles.hips)].clone();
      const eye_ws = eye.getWorldPosition(new THREE.Vector3());
      const distance = Math.hypot(hips.x - eye_ws.x, hips.z - eye_ws.z);
      // Cosine between where the partner faces and the way to the eye, on the floor.
      const to_eye = new THREE.Vector3(eye_ws.x - hips.x, 0, eye_ws.z - hips.z).normalize();
      const faces = state.partner.facing(new THREE.Vector3()).dot(to_eye);
      const ndc = hips.project(eye);
      const head = state.user?.roles.head ?? -1;
      const drawn = (joint) => joint >= 0 && !!state.user?.jointMeshes[joint].visible;
      return {
        hips_ndc: ndc.toArray(),
        hips_distance_m: distance,
        partner_head_height_m: state.partner.headPosition().y,
        partner_faces_eye_cos: faces,
        eye_ws: eye_ws.toArray(),
        user_head_drawn: drawn(head),
        user_hands_drawn: drawn(state.user?.roles.left_wrist ?? -1) && drawn(state.user?.roles.right_wrist ?? -1),
        user_points_only: !!state.user?.pointsOnly,
        // How far each hand block is drawn from the server's wrist (the controller's grip offset).
        user_hand_blocks_from_wrists_m: [state.user?.roles.left_wrist ?? -1, state.user?.roles.right_wrist ?? -1].map(
          (j) => (j >= 0 ? state.user.jointMeshes[j].position.distanceTo(state.user.positions_ws[j]) : null)),
      };
    },
    /** CSS colours of the figures now: {user, partner}. */
    get colors() {
      return { user: '#' + state.user?.material.color.getHexString(), partner: '#' + state.partner?.material.color.getHexString() };
    },
    /** Joint positions of 'user' or 'partner' in page pixels, as last drawn. */
    screenJoints(which) { return project(which === 'partner' ? state.partner : state.user); },
    /** World positions of the user's head and of the camera (rig included). */
    userHead() { return state.user?.posed ? state.user.headPosition().toArray() : null; },
    userFacing() { return state.user?.posed ? state.user.facing().toArray() : null; },
    cameraWorld() { return camera.getWorldPosition(new THREE.Vector3()).toArray(); },
    rigWorld() { return rig.position.toArray(); },
    /** Stops (true) or resumes (false) applying frames, so a screenshot matches screenJoints. */
    freeze(on) { state.frozen = !!on; },
    exitXR() { return renderer.xr.getSession()?.end(); },
    viewSideOn,
    /** The timeline's view of the follower: current entry, jumps seen, takes known, and its
     *  last drawn layout (plot edges, where confidence 1 and 0 sit, the labelled time ticks). */
    get timeline() {
      const L = timeline.lastLayout;
      return {
        current: timeline.current,
        jumps: timeline.jumps.length,
        takes: timeline.takes.length,
        layout: L && {
          plotTop: L.plotTop, plotBottom: L.plotBottom, yOne: L.yOne, yZero: L.yZero,
          dotRadius: L.dotRadius, labelTop: L.labelTop, x0: L.x0, x1: L.x1,
          cursorX: timeline.current ? L.x_of(timeline.current.frame) : null,
          ticks: L.ticks.map(({ seconds, label, x }) => ({ seconds, label, x })),
        },
      };
    },
    /** The replay as the viewer sees it: the server's last state, the position now, and how
     *  many states came (null state: the source is not a replay). */
    get replay() {
      return {
        state: replay.state && { ...replay.state },
        received_ms: replay.received_ms,
        position_s: replayPosition(),
        states: replay.states,
        visible: !ui.replay.hidden,
      };
    },
    /** Segments of the floor grid along each axis. */
    get floorGrid() { return { ...grid.userData.segments }; },
    renderer,
    send: (msg) => connection.send(msg),
  };
}

main().catch((err) => {
  console.error('duet viewer failed to start', err);
  const status = document.getElementById('status-conn');
  if (status) status.textContent = `viewer failed: ${err.message}`;
});
