// Opens the two BVH files `duet follow` wrote with three.js's own BVHLoader (the one the examples
// use; three from web/node_modules) and checks that the dancers are where duet says they are.
//
//   node web/tests/bvh-loader-check.mjs --user USER.bvh --partner PARTNER.bvh \
//     --reference REFERENCE.json [--tolerance-mm 1] [--report REPORT.json]
//
// REFERENCE.json is written by viewer_reference (tests/viewers/viewer_reference.cc): world
// positions (metres, BVH axes, y up) of every joint of both dancers at the checked frames, from
// duet's reader and forward kinematics, plus the contact frames. Runs in plain Node (no DOM):
// loader.parse(text) gives {skeleton, clip}; the clip is played on the skeleton's root bone with an
// AnimationMixer (LoopOnce, clamped) set to each checked frame's time, and each bone's world
// position is read after updateMatrixWorld. three is y-up like BVH: no axis conversion; positions
// are scaled by the file's metres per unit (duet writes in the source files' units; the reference
// gives the scale). Checked, as in tests/viewers/blender_import_check.py:
// - every track has the file's frame count, keyed every 1/fps seconds;
// - at every checked frame, every bone's world position equals duet's within the tolerance;
// - both dancers upright on the floor (hips 0.6-1.3 m high, lowest ankle below 0.25 m); hips
//   0.2-2.5 m apart horizontally and within 0.15 m of the couple's spacing in the capture at the
//   follower's template frame; at contact frames the held wrists as far apart as in the capture
//   at the template frame, within 0.15 m (a check of the shared world frame and the couple's
//   arrangement; how exactly the contact IK holds the captured grip is measured by `duet eval`).
// Not part of `npm test` (the name does not match node --test's patterns): run by
// tests/viewers/check_bvh_in_viewers.sh (CTest bvh_output_in_blender_and_threejs).
import { readFileSync, writeFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { AnimationMixer, LoopOnce, Vector3, REVISION } from 'three';
import { BVHLoader } from 'three/examples/jsm/loaders/BVHLoader.js';

const { values: args } = parseArgs({
  options: {
    user: { type: 'string' },
    partner: { type: 'string' },
    reference: { type: 'string' },
    'tolerance-mm': { type: 'string', default: '1' },
    report: { type: 'string' },
  },
});
for (const name of ['user', 'partner', 'reference']) {
  if (!args[name]) {
    console.error(`bvh-loader-check: --${name} is required`);
    process.exit(2);
  }
}
const ref = JSON.parse(readFileSync(args.reference, 'utf8'));
const tolerance = Number(args['tolerance-mm']) / 1000;
const failures = [];

function load(path) {
  const { skeleton, clip } = new BVHLoader().parse(readFileSync(path, 'utf8'));
  const root = skeleton.bones[0];
  const mixer = new AnimationMixer(root);
  const action = mixer.clipAction(clip);
  action.setLoop(LoopOnce, 1);
  action.clampWhenFinished = true;
  action.play();
  const bones = new Map(skeleton.bones.map((b) => [b.name, b]));
  return { clip, root, mixer, bones };
}

const dancers = { user: load(args.user), partner: load(args.partner) };

for (const [who, d] of Object.entries(dancers)) {
  for (const track of d.clip.tracks) {
    const times = track.times;
    const steps = [];
    for (let i = 1; i < times.length; i++) steps.push(times[i] - times[i - 1]);
    const badStep = steps.find((s) => Math.abs(s - 1 / ref.fps) > 1e-6);
    if (times.length !== ref.frames || badStep !== undefined) {
      failures.push(`${who}: track ${track.name} has ${times.length} keys` +
        (badStep !== undefined ? ` and a step of ${badStep} s` : '') +
        `; reference ${ref.frames} frames at ${ref.fps} fps`);
      break;
    }
  }
  const missing = ref.joints[who].filter((n) => !d.bones.has(n));
  if (missing.length) failures.push(`${who}: bones missing in three.js: ${missing.join(', ')}`);
}

const maxDiff = { user: 0, partner: 0 };
const worst = { user: null, partner: null };
const positions = { user: [], partner: [] }; // per checked frame: Map name -> [x, y, z]
const v = new Vector3();
ref.frames_checked.forEach((frame, i) => {
  for (const [who, d] of Object.entries(dancers)) {
    d.mixer.setTime(frame / ref.fps);
    d.root.updateMatrixWorld(true);
    const world = new Map();
    ref.joints[who].forEach((name, k) => {
      const bone = d.bones.get(name);
      if (!bone) return;
      bone.getWorldPosition(v);
      const s = ref.metres_per_unit[who];  // the file's units to metres
      const p = [v.x * s, v.y * s, v.z * s];
      world.set(name, p);
      const diff = Math.hypot(...p.map((c, a) => c - ref[who][i][k][a]));
      if (diff > maxDiff[who]) {
        maxDiff[who] = diff;
        worst[who] = [frame, name];
      }
    });
    positions[who].push(world);
  }
});
for (const who of Object.keys(dancers)) {
  if (maxDiff[who] > tolerance) {
    failures.push(`${who}: a joint is ${(maxDiff[who] * 1000).toFixed(3)} mm from duet's ` +
      `position (frame ${worst[who][0]}, ${worst[who][1]}); tolerance ${args['tolerance-mm']} mm`);
  }
}

// Where the dancers belong (three's own positions; y up).
const roles = ref.roles;
let minHips = Infinity;
let maxHips = 0;
let maxHand = 0;
let maxSpacing = 0;
ref.frames_checked.forEach((frame, i) => {
  const u = positions.user[i];
  const p = positions.partner[i];
  for (const [who, pos] of [['user', u], ['partner', p]]) {
    const r = roles[who];
    const hipsY = pos.get(r.hips)[1];
    const footY = Math.min(pos.get(r.left_ankle)[1], pos.get(r.right_ankle)[1]);
    if (!(hipsY >= 0.6 && hipsY <= 1.3) || footY > 0.25) {
      failures.push(`${who} at frame ${frame}: hips ${hipsY.toFixed(3)} m and lowest ankle ` +
        `${footY.toFixed(3)} m above the floor (want 0.6-1.3 m and < 0.25 m)`);
    }
  }
  const hu = u.get(roles.user.hips);
  const hp = p.get(roles.partner.hips);
  const dist = Math.hypot(hu[0] - hp[0], hu[2] - hp[2]);
  minHips = Math.min(minHips, dist);
  maxHips = Math.max(maxHips, dist);
  const captured = ref.captured_hips_distance_m[i];
  maxSpacing = Math.max(maxSpacing, Math.abs(dist - captured));
  if (!(dist >= 0.2 && dist <= 2.5) || Math.abs(dist - captured) > 0.15) {
    failures.push(`frame ${frame}: hips ${dist.toFixed(3)} m apart horizontally, in the capture ` +
      `${captured.toFixed(3)} m (want 0.2-2.5 m and within 0.15 m of the capture)`);
  }
});
for (const c of ref.contacts) {
  const i = ref.frames_checked.indexOf(c.frame);
  const a = positions.user[i].get(c.user_joint);
  const b = positions.partner[i].get(c.partner_joint);
  const dist = Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  maxHand = Math.max(maxHand, Math.abs(dist - c.captured_distance_m));
  if (Math.abs(dist - c.captured_distance_m) > 0.15) {
    failures.push(`contact frame ${c.frame} (${c.pair}): user ${c.user_joint} and partner ` +
      `${c.partner_joint} ${dist.toFixed(3)} m apart, in the capture ` +
      `${c.captured_distance_m.toFixed(3)} m (want within 0.15 m)`);
  }
}

const round = (x, n) => Number(x.toFixed(n));
const report = {
  viewer: `three.js r${REVISION} BVHLoader`,
  frames_checked: ref.frames_checked.length,
  contact_frames: ref.contacts.length,
  max_diff_mm: { user: round(maxDiff.user * 1000, 4), partner: round(maxDiff.partner * 1000, 4) },
  hips_distance_m: [round(minHips, 3), round(maxHips, 3)],
  max_hips_distance_vs_capture_m: round(maxSpacing, 4),
  max_contact_hand_vs_capture_m: round(maxHand, 4),
  fps: ref.fps,
  failures,
};
console.log(`bvh-loader-check: ${JSON.stringify(report)}`);
if (args.report) writeFileSync(args.report, JSON.stringify(report, null, 2));
if (failures.length) {
  for (const msg of failures.slice(0, 20)) console.error(`bvh-loader-check: FAIL: ${msg}`);
  process.exit(1);
}
