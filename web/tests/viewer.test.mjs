// Browser test of the viewer (node --test; playwright-core driving Debian's Chromium).
//
// Against a real server: DUET_VIEWER_URL=http://127.0.0.1:PORT/ node --test tests/
// Without it, starts tests/mock-server.mjs on a free port (needs `npm run build` first).
// DUET_CHROMIUM overrides the browser (default /usr/bin/chromium). Screenshots of the
// pixel-checked views and of VR go to web/test-results/.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, mkdirSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { startMockServer } from './mock-server.mjs';
import { kChromium, kLaunchArgs } from './chromium.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const kDist = path.resolve(here, '..', 'dist');
const kResults = path.resolve(here, '..', 'test-results');
const kViewport = { width: 1280, height: 720 };
const kLeaderBlue = '#2f6fff';
const kPartnerPink = '#ff4fa3';

const real_url = process.env.DUET_VIEWER_URL || '';
const against = real_url ? `real server ${real_url}` : 'mock server';

let mock = null; // set when testing against the mock
let base_url = '';
let browser = null;
let page = null;
let streaming = false; // the first test saw frames; the others fail fast without them

function requireFrames() {
  assert.ok(streaming, 'no frames from the server (see the first test); skipping the wait');
}

/** Waits until `fn(arg)` is truthy in the page; on timeout fails naming `what` and the state. */
async function waitUntil(p, what, fn, arg, timeout_s = 10) {
  try {
    await p.waitForFunction(fn, arg, { timeout: timeout_s * 1000, polling: 50 });
  } catch (err) {
    const snapshot = await p
      .evaluate(() => {
        const v = window.duetViewer;
        if (!v) return 'window.duetViewer is missing (viewer did not start)';
        return JSON.stringify({
          connected: v.connected,
          framesReceived: v.framesReceived,
          renderCount: v.renderCount,
          xrPresenting: v.xrPresenting,
          cameraMode: v.cameraMode,
          role: v.role,
          errors: v.errors,
          corrections: v.lastFrame?.corrections,
        });
      })
      .catch((e) => `page unreachable: ${e.message}`);
    throw new Error(`timed out after ${timeout_s} s waiting for: ${what}\n  viewer state: ${snapshot}\n  (${err.message.split('\n')[0]})`);
  }
}

/** Waits until the mock server has recorded a client message matching `match`. */
async function waitForReceived(what, match, timeout_s = 5) {
  const deadline = Date.now() + timeout_s * 1000;
  while (Date.now() < deadline) {
    const hit = mock.received.find(match);
    if (hit) return hit;
    await new Promise((r) => setTimeout(r, 25));
  }
  throw new Error(`mock server did not receive ${what} within ${timeout_s} s; it received: ${JSON.stringify(mock.received)}`);
}

function urlWith(url, params) {
  const u = new URL(url);
  for (const [k, v] of Object.entries(params)) u.searchParams.set(k, v);
  return u.toString();
}

async function openViewer(url) {
  const p = await browser.newPage({ viewport: kViewport, deviceScaleFactor: 1 });
  p.setDefaultTimeout(10000); // clicks on a control that never becomes enabled
  p.on('pageerror', (err) => console.error(`[page error] ${err.message}`));
  p.on('console', (msg) => {
    if (msg.type() === 'error') console.error(`[page console] ${msg.text()}`);
  });
  await p.goto(url, { waitUntil: 'load', timeout: 15000 });
  await waitUntil(p, 'the viewer to start (window.duetViewer)', () => !!window.duetViewer, null, 10);
  return p;
}

/** Counts blue-ish and pink-ish pixels of a PNG screenshot inside boxes, decoding in the page. */
async function countColours(p, png, boxes, masks) {
  return p.evaluate(
    async ({ b64, boxes, masks }) => {
      const img = new Image();
      img.src = `data:image/png;base64,${b64}`;
      await img.decode();
      const c = document.createElement('canvas');
      c.width = img.width;
      c.height = img.height;
      const ctx = c.getContext('2d', { willReadFrequently: true });
      ctx.drawImage(img, 0, 0);
      const { data, width, height } = ctx.getImageData(0, 0, c.width, c.height);
      const blue = (r, g, b) => b >= 90 && b > r + 50 && b > g + 25;
      const pink = (r, g, b) => r >= 120 && r > g + 60 && b > g + 15 && r > b;
      const inside = (x, y, bx) => x >= bx.x0 && x <= bx.x1 && y >= bx.y0 && y <= bx.y1;
      const out = { total: { blue: 0, pink: 0 }, centroid: { blue: [0, 0], pink: [0, 0] } };
      for (const name of Object.keys(boxes)) out[name] = { blue: 0, pink: 0 };
      for (let y = 0; y < height; ++y) {
        for (let x = 0; x < width; ++x) {
          if (masks.some((m) => inside(x, y, m))) continue; // UI panels over the canvas
          const i = 4 * (y * width + x);
          const kind = blue(data[i], data[i + 1], data[i + 2]) ? 'blue' : pink(data[i], data[i + 1], data[i + 2]) ? 'pink' : null;
          if (!kind) continue;
          out.total[kind] += 1;
          out.centroid[kind][0] += x;
          out.centroid[kind][1] += y;
          for (const [name, bx] of Object.entries(boxes)) if (inside(x, y, bx)) out[name][kind] += 1;
        }
      }
      for (const kind of ['blue', 'pink']) {
        const n = Math.max(1, out.total[kind]);
        out.centroid[kind] = out.centroid[kind].map((v) => Math.round(v / n));
      }
      return out;
    },
    { b64: png.toString('base64'), boxes, masks },
  );
}

function boxOf(points, pad) {
  const on_screen = points.filter((q) => q.z < 1 && Number.isFinite(q.x) && Number.isFinite(q.y));
  if (!on_screen.length) return null;
  const xs = on_screen.map((q) => q.x);
  const ys = on_screen.map((q) => q.y);
  return {
    x0: Math.round(Math.min(...xs) - pad),
    x1: Math.round(Math.max(...xs) + pad),
    y0: Math.round(Math.min(...ys) - pad),
    y1: Math.round(Math.max(...ys) + pad),
  };
}

const centre = (b) => [(b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2];
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/** Runs of floor-grid pixels (dim grey-blue lines on the dark floor) crossed along one row and
 *  one column of a PNG screenshot, UI panels masked out. */
async function gridCrossings(p, png, row_y, column_x, y_range, masks) {
  return p.evaluate(
    async ({ b64, row_y, column_x, y_range, masks }) => {
      const img = new Image();
      img.src = `data:image/png;base64,${b64}`;
      await img.decode();
      const c = document.createElement('canvas');
      c.width = img.width;
      c.height = img.height;
      const ctx = c.getContext('2d', { willReadFrequently: true });
      ctx.drawImage(img, 0, 0);
      const { data, width } = ctx.getImageData(0, 0, c.width, c.height);
      const masked = (x, y) => masks.some((m) => x >= m.x0 && x <= m.x1 && y >= m.y0 && y <= m.y1);
      // Background 0x15171c (sum 72); grid 0x2c3038 (sum 148), centre line 0x5a6070.
      const grid = (x, y) => {
        const i = 4 * (y * width + x);
        const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
        return Math.max(r, g, b) - Math.min(r, g, b) <= 24 && r + g + b >= 100 && r + g + b <= 420;
      };
      const runs = (points) => {
        let n = 0;
        let inside = false;
        for (const [x, y] of points) {
          const on = !masked(x, y) && grid(x, y);
          if (on && !inside) n += 1;
          inside = on;
        }
        return n;
      };
      const row = [];
      for (let x = 0; x < c.width; ++x) row.push([x, row_y]);
      const column = [];
      for (let y = y_range[0]; y <= y_range[1]; ++y) column.push([column_x, y]);
      return { row: runs(row), column: runs(column) };
    },
    { b64: png.toString('base64'), row_y, column_x, y_range, masks },
  );
}
const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);

/** Screenshot with frames frozen, so the figures' projected joints match the pixels. */
async function frozenShot(p, name) {
  await p.evaluate(() => window.duetViewer.freeze(true));
  const count = await p.evaluate(() => window.duetViewer.renderCount);
  await waitUntil(p, 'two renders after freezing', (n) => window.duetViewer.renderCount >= n + 2, count, 5);
  const png = await p.screenshot({ type: 'png' });
  const user = await p.evaluate(() => window.duetViewer.screenJoints('user'));
  const partner = await p.evaluate(() => window.duetViewer.screenJoints('partner'));
  const masks = await p.evaluate(() =>
    ['panel', 'timeline'].map((id) => {
      const r = document.getElementById(id).getBoundingClientRect();
      return { x0: Math.floor(r.left), y0: Math.floor(r.top), x1: Math.ceil(r.right), y1: Math.ceil(r.bottom) };
    }),
  );
  await p.evaluate(() => window.duetViewer.freeze(false));
  mkdirSync(kResults, { recursive: true });
  writeFileSync(path.join(kResults, `${name}.png`), png);
  return { png, user, partner, masks };
}

describe(`duet viewer (${against})`, () => {
  before(async () => {
    assert.ok(existsSync(kChromium), `no browser at ${kChromium}: apt-get install -y chromium (or set DUET_CHROMIUM)`);
    if (real_url) {
      base_url = real_url;
    } else {
      assert.ok(existsSync(path.join(kDist, 'index.html')), `no ${kDist}/index.html: run npm run build first`);
      mock = await startMockServer({ port: 0 });
      base_url = mock.url;
    }
    browser = await chromium.launch({ executablePath: kChromium, args: kLaunchArgs, timeout: 20000 });
    page = await openViewer(base_url);
  });

  after(async () => {
    await browser?.close();
    await mock?.close();
  });

  test('connects, gets hello, receives frames and renders', async () => {
    await waitUntil(page, 'a connection and 30 frames', () => window.duetViewer.connected && window.duetViewer.framesReceived >= 30, null, 15);
    await waitUntil(page, '10 renders', () => window.duetViewer.renderCount >= 10, null, 10);
    streaming = true;
    const info = await page.evaluate(() => ({
      hello: window.duetViewer.hello,
      frame: window.duetViewer.lastFrame,
      colors: window.duetViewer.colors,
      role: window.duetViewer.role,
    }));
    assert.equal(info.hello.type, 'hello');
    assert.equal(info.frame.user.positions.length, info.hello.user_skeleton.joints.length, 'user joints in frame vs hello');
    assert.equal(info.frame.partner.positions.length, info.hello.partner_skeleton.joints.length, 'partner joints in frame vs hello');
    // Colours by dance role (paper fig. 2): leader blue, partner pink.
    const leader_is_user = info.role === 'leader';
    assert.equal(info.colors.user, leader_is_user ? kLeaderBlue : kPartnerPink);
    assert.equal(info.colors.partner, leader_is_user ? kPartnerPink : kLeaderBlue);
  });

  test('draws the leader blue and the partner pink where the figures are', async (t) => {
    requireFrames();
    await page.evaluate(() => window.duetViewer.viewSideOn());
    const shot = await frozenShot(page, 'orbit');
    const role = await page.evaluate(() => window.duetViewer.role);
    const user_box = boxOf(shot.user, 30);
    const partner_box = boxOf(shot.partner, 30);
    assert.ok(user_box && partner_box, 'both figures project into the view');
    const counts = await countColours(page, shot.png, { user: user_box, partner: partner_box }, shot.masks);
    // With the user as leader, the user's figure is blue and the partner's pink.
    const user_colour = role === 'leader' ? 'blue' : 'pink';
    const partner_colour = role === 'leader' ? 'pink' : 'blue';
    t.diagnostic(
      `pixels: total blue ${counts.total.blue}, pink ${counts.total.pink}; ` +
        `in user box ${JSON.stringify(user_box)} ${user_colour} ${counts.user[user_colour]}; ` +
        `in partner box ${JSON.stringify(partner_box)} ${partner_colour} ${counts.partner[partner_colour]}; ` +
        `centroids blue ${counts.centroid.blue} pink ${counts.centroid.pink}`,
    );
    assert.ok(counts.user[user_colour] >= 300, `user figure (${user_colour}) pixels in its box: ${counts.user[user_colour]} < 300`);
    assert.ok(counts.partner[partner_colour] >= 300, `partner figure (${partner_colour}) pixels in its box: ${counts.partner[partner_colour]} < 300`);
    // Each colour sits over its own figure, not the other one.
    const c_user_colour = counts.centroid[user_colour];
    const c_partner_colour = counts.centroid[partner_colour];
    assert.ok(dist(c_user_colour, centre(user_box)) < dist(c_user_colour, centre(partner_box)), `${user_colour} centroid ${c_user_colour} is nearer the partner's figure`);
    assert.ok(dist(c_partner_colour, centre(partner_box)) < dist(c_partner_colour, centre(user_box)), `${partner_colour} centroid ${c_partner_colour} is nearer the user's figure`);
  });

  test('the floor grid has lines along both axes', async (t) => {
    requireFrames();
    const segments = await page.evaluate(() => window.duetViewer.floorGrid);
    assert.ok(segments.alongX > 0 && segments.alongX === segments.alongZ, `grid segments ${JSON.stringify(segments)}`);
    await page.evaluate(() => window.duetViewer.viewSideOn());
    const shot = await frozenShot(page, 'floor-grid');
    const [panel, timeline] = shot.masks;
    const feet_y = Math.max(...[...shot.user, ...shot.partner].filter((q) => q.z < 1).map((q) => q.y));
    // Side-on, the floor between the feet and the timeline is crossed mostly by the lines that
    // run away from the camera; a column at the left edge mostly by the lines across the view.
    const row_y = Math.round((Math.min(feet_y, timeline.y0) + timeline.y0) / 2);
    const crossings = await gridCrossings(page, shot.png, row_y, 20, [panel.y1 + 2, timeline.y0 - 2], shot.masks);
    t.diagnostic(`grid lines crossed: row y=${row_y} ${crossings.row}, column x=20 ${crossings.column}`);
    assert.ok(crossings.row >= 6, `only ${crossings.row} grid lines cross the row at y=${row_y} (lines away from the camera missing?)`);
    assert.ok(crossings.column >= 6, `only ${crossings.column} grid lines cross the column at x=20 (lines across the view missing?)`);
  });

  test('a correction switch sends set and follows frame.corrections', async () => {
    requireFrames();
    const before_state = await page.evaluate(() => window.duetViewer.lastFrame.corrections.smooth);
    const target = !before_state;
    await page.click('#corr-smooth');
    if (mock) {
      await waitForReceived(`{"type":"set","correction":"smooth","enabled":${target}}`, (m) => m.type === 'set' && m.correction === 'smooth' && m.enabled === target);
    }
    await waitUntil(page, `frame.corrections.smooth === ${target}`, (v) => window.duetViewer.lastFrame.corrections.smooth === v, target, 5);
    await waitUntil(page, `the smooth checkbox to show ${target}`, (v) => document.getElementById('corr-smooth').checked === v, target, 5);
    // Switch it back, leaving the server as it was.
    await page.click('#corr-smooth');
    await waitUntil(page, `frame.corrections.smooth back to ${before_state}`, (v) => window.duetViewer.lastFrame.corrections.smooth === v, before_state, 5);
    assert.equal(await page.isChecked('#corr-smooth'), before_state);
  });

  test('a bad message is answered with an error that the viewer shows', async () => {
    requireFrames();
    const n = await page.evaluate(() => window.duetViewer.errors.length);
    await page.evaluate(() => window.duetViewer.send({ type: 'set', correction: 'no-such-correction', enabled: true }));
    await waitUntil(page, 'an error reply', (k) => window.duetViewer.errors.length > k, n, 5);
    const text = await page.textContent('#status-error');
    assert.match(text, /server:/);
    const frames = await page.evaluate(() => window.duetViewer.framesReceived);
    await waitUntil(page, 'frames after the error', (k) => window.duetViewer.framesReceived > k + 10, frames, 5);
  });

  test('the server\'s advice to calibrate is shown while it lasts', { skip: real_url ? 'the mock server sets the advice' : false }, async () => {
    requireFrames();
    assert.equal(await page.isHidden('#status-advice'), true, 'no advice before the server gives one');
    mock.state.advice = { calibrate: { rig_offset: 0.094 } };
    await waitUntil(page, 'the advice shown', () => !document.getElementById('status-advice').hidden, undefined, 5);
    const text = await page.textContent('#status-advice');
    assert.match(text, /learnt offset 0\.094/);
    assert.match(text, /arms held straight forward/);
    // The VR panel holds the same words, hidden outside VR.
    const hud = await page.evaluate(() => window.duetViewer.adviceHud);
    assert.equal(hud.text, text);
    assert.equal(hud.visible, false);
    mock.state.advice = null;
    await waitUntil(page, 'the advice gone', () => document.getElementById('status-advice').hidden, undefined, 5);
  });

  test('role switch and reset send their messages; colours follow the dance role', async () => {
    requireFrames();
    const start_role = await page.evaluate(() => window.duetViewer.role);
    const other = start_role === 'leader' ? 'partner' : 'leader';
    await page.selectOption('#role', other);
    if (mock) await waitForReceived(`{"type":"role","role":"${other}"}`, (m) => m.type === 'role' && m.role === other);
    await waitUntil(page, `role ${other}`, (r) => window.duetViewer.role === r, other, 5);
    const colors = await page.evaluate(() => window.duetViewer.colors);
    assert.equal(colors.user, other === 'leader' ? kLeaderBlue : kPartnerPink, 'user colour after the switch');
    assert.equal(colors.partner, other === 'leader' ? kPartnerPink : kLeaderBlue, 'partner colour after the switch');
    let frames = await page.evaluate(() => window.duetViewer.framesReceived);
    await waitUntil(page, 'frames after the role switch', (k) => window.duetViewer.framesReceived > k + 10, frames, 5);

    await page.selectOption('#role', start_role);
    if (mock) await waitForReceived(`{"type":"role","role":"${start_role}"}`, (m) => m.type === 'role' && m.role === start_role);
    await waitUntil(page, `role back to ${start_role}`, (r) => window.duetViewer.role === r, start_role, 5);

    await page.click('#reset');
    if (mock) await waitForReceived('{"type":"reset"}', (m) => m.type === 'reset');
    frames = await page.evaluate(() => window.duetViewer.framesReceived);
    await waitUntil(page, 'frames after reset', (k) => window.duetViewer.framesReceived > k + 10, frames, 5);
  });

  test('first-person view puts the camera at the user head, the partner in view', async (t) => {
    requireFrames();
    await page.click('#view');
    await waitUntil(page, 'first-person mode', () => window.duetViewer.cameraMode === 'first-person', null, 5);
    const shot = await frozenShot(page, 'first-person');
    const { head, cam } = await page.evaluate(() => ({ head: window.duetViewer.userHead(), cam: window.duetViewer.cameraWorld() }));
    const d = Math.hypot(head[0] - cam[0], head[1] - cam[1], head[2] - cam[2]);
    assert.ok(d < 0.15, `camera ${cam} is ${d.toFixed(3)} m from the user's head ${head}`);
    const role = await page.evaluate(() => window.duetViewer.role);
    const counts = await countColours(page, shot.png, {}, shot.masks);
    const partner_colour = role === 'leader' ? 'pink' : 'blue';
    t.diagnostic(`first-person pixels: blue ${counts.total.blue}, pink ${counts.total.pink}`);
    // The mock's partner always faces the user; a real take may turn away (open breaks).
    if (mock) assert.ok(counts.total[partner_colour] >= 1000, `partner (${partner_colour}) pixels in first person: ${counts.total[partner_colour]}`);
    await page.click('#view');
    await waitUntil(page, 'orbit mode again', () => window.duetViewer.cameraMode === 'orbit', null, 5);
  });

  test('reconnects after the server drops the connection', { skip: real_url ? 'needs the mock server' : false }, async () => {
    requireFrames();
    mock.dropClients();
    await waitUntil(page, 'the viewer to notice the drop', () => !window.duetViewer.connected, null, 5);
    assert.match(await page.textContent('#status-conn'), /disconnected/);
    const frames = await page.evaluate(() => window.duetViewer.framesReceived);
    await waitUntil(page, 'reconnection and new frames', (k) => window.duetViewer.connected && window.duetViewer.framesReceived > k + 10, frames, 10);
    assert.match(await page.textContent('#status-conn'), /^connected/);
  });

  test('the timeline shows the take, the template frame and jumps', async () => {
    requireFrames();
    const tl = await page.evaluate(() => window.duetViewer.timeline);
    const hello = await page.evaluate(() => window.duetViewer.hello);
    assert.equal(tl.takes, hello.takes.length);
    assert.ok(tl.current, 'timeline has a current template position');
    assert.ok(tl.current.frame >= 0 && tl.current.frame <= hello.takes[tl.current.take].frames);
    if (mock) {
      // The mock jumps every 4 s.
      await waitUntil(page, 'a jump mark', () => window.duetViewer.timeline.jumps >= 1, null, 6);
    }
  });

  test('the timeline labels its time axis and keeps confidence 1 inside the plot', async (t) => {
    requireFrames();
    const { tl, hello } = await page.evaluate(() => ({ tl: window.duetViewer.timeline, hello: window.duetViewer.hello }));
    const L = tl.layout;
    assert.ok(L, 'the timeline has been drawn');
    const take = hello.takes[tl.current.take];
    const duration_s = take.frames / hello.fps;
    assert.ok(L.ticks.length >= 3, `time ticks: ${JSON.stringify(L.ticks)}`);
    assert.equal(L.ticks[0].seconds, 0);
    for (let k = 1; k < L.ticks.length; ++k) {
      assert.ok(L.ticks[k].seconds > L.ticks[k - 1].seconds && L.ticks[k].x > L.ticks[k - 1].x, `ticks out of order: ${JSON.stringify(L.ticks)}`);
    }
    assert.ok(L.ticks.at(-1).seconds <= duration_s + 1e-6, `last tick past the take's ${duration_s} s`);
    for (const tick of L.ticks) assert.match(tick.label, /^(\d+ s|\d+:\d\d)$/);
    assert.equal(new Set(L.ticks.map((k) => k.label)).size, L.ticks.length, 'labels are distinct');
    // The cursor's dot at confidence 1 (and 0) lies whole inside the plot.
    assert.ok(L.yOne - L.dotRadius >= L.plotTop, `confidence 1 at y=${L.yOne} is clipped by the plot top ${L.plotTop}`);
    assert.ok(L.yZero + L.dotRadius <= L.plotBottom, `confidence 0 at y=${L.yZero} is clipped by the plot bottom ${L.plotBottom}`);
    // Every label is drawn: light text pixels under its tick.
    const lit = await page.evaluate((ticks) => {
      const canvas = document.getElementById('timeline');
      const ratio = canvas.width / canvas.clientWidth;
      const { labelTop } = window.duetViewer.timeline.layout;
      const ctx = canvas.getContext('2d');
      return ticks.map((tick) => {
        const x0 = Math.max(0, Math.round((tick.x - 14) * ratio));
        const x1 = Math.min(canvas.width, Math.round((tick.x + 14) * ratio));
        const img = ctx.getImageData(x0, Math.round(labelTop * ratio), x1 - x0, Math.round(11 * ratio)).data;
        let n = 0;
        for (let i = 0; i < img.length; i += 4) if (img[i + 3] > 100 && img[i] + img[i + 1] + img[i + 2] > 300) n += 1;
        return n;
      });
    }, L.ticks);
    lit.forEach((n, k) => assert.ok(n >= 5, `tick label "${L.ticks[k].label}" has ${n} lit pixels`));

    // When the confidence is 1, its dot is drawn whole at the top of the plot.
    try {
      await page.waitForFunction(() => {
        const v = window.duetViewer;
        if (!(v.timeline.current?.confidence >= 1)) return false;
        v.freeze(true); // holds the timeline at this frame
        return true;
      }, null, { timeout: mock ? 9000 : 6000, polling: 20 });
    } catch {
      assert.ok(!mock, 'the mock reaches confidence 1 every 7 s');
      t.diagnostic('the confidence did not reach 1 within 6 s; the pixel check of the top edge is skipped');
      return;
    }
    try {
      const n = await page.evaluate(() => window.duetViewer.renderCount);
      await waitUntil(page, 'two renders after freezing', (k) => window.duetViewer.renderCount >= k + 2, n, 5);
      const dot = await page.evaluate(() => {
        const canvas = document.getElementById('timeline');
        const ratio = canvas.width / canvas.clientWidth;
        const L = window.duetViewer.timeline.layout;
        const ctx = canvas.getContext('2d');
        const white = (x, y) => {
          const d = ctx.getImageData(Math.round(x * ratio), Math.round(y * ratio), 1, 1).data;
          return d[0] > 200 && d[1] > 200 && d[2] > 200 && d[3] > 200;
        };
        const x = L.cursorX;
        const y = L.yOne;
        return { x, y, left: white(x - 3, y), right: white(x + 3, y), upper: white(x - 2, y - 2), lower: white(x - 2, y + 2) };
      });
      t.diagnostic(`confidence-1 dot: ${JSON.stringify(dot)}`);
      assert.ok(dot.left && dot.right && dot.upper && dot.lower, `the dot at confidence 1 is not whole: ${JSON.stringify(dot)}`);
    } finally {
      await page.evaluate(() => window.duetViewer.freeze(false));
    }
  });

  test('replay controls pause, seek and set the speed of a file replay', async (t) => {
    requireFrames();
    const viewer = () => page.evaluate(() => window.duetViewer.replay);
    // duet serve --source replay:... and the mock say where the file is once a second.
    await waitUntil(page, 'a replay_state (the server plays a file)', () => window.duetViewer.replay.visible, null, 5);
    let r = await viewer();
    if (r.state.paused) {
      await page.click('#replay-play');
      await waitUntil(page, 'playing', () => window.duetViewer.replay.state.paused === false, null, 5);
      r = await viewer();
    }
    const duration_s = r.state.duration_s;
    assert.ok(duration_s > 1, `duration ${duration_s}`);

    // Pause: the server confirms, the button offers Play, and frames stop.
    await page.click('#replay-play');
    if (mock) await waitForReceived('{"type":"replay","paused":true}', (m) => m.type === 'replay' && m.paused === true);
    await waitUntil(page, 'the server to confirm the pause', (n) => window.duetViewer.replay.states > n && window.duetViewer.replay.state.paused, r.states, 5);
    assert.equal((await page.textContent('#replay-play')).trim(), 'Play');
    await sleep(300); // frames already on their way
    const f0 = await page.evaluate(() => window.duetViewer.framesReceived);
    await sleep(1000);
    const f1 = await page.evaluate(() => window.duetViewer.framesReceived);
    assert.ok(f1 - f0 <= 1, `${f1 - f0} frames in a second while paused`);

    // Seek with the slider to the middle: the server goes there, still paused, and sends that
    // one frame so the dancers show it.
    const target = Math.round(duration_s / 2);
    r = await viewer();
    await page.$eval('#replay-seek', (el, v) => {
      el.value = String(v);
      el.dispatchEvent(new Event('input', { bubbles: true }));
      el.dispatchEvent(new Event('change', { bubbles: true }));
    }, target);
    if (mock) await waitForReceived(`{"type":"replay","seek_s":${target}}`, (m) => m.type === 'replay' && m.seek_s === target);
    await waitUntil(page, `the server at ${target} s`, ([n, v]) => {
      const s = window.duetViewer.replay;
      return s.states > n && Math.abs(s.state.position_s - v) < 0.5 && s.state.paused;
    }, [r.states, target], 5);
    await waitUntil(page, 'the frame sought to', (k) => window.duetViewer.framesReceived > k, f1, 5);
    assert.match(await page.textContent('#replay-time'), new RegExp(`^${target}\\.\\d / ${duration_s.toFixed(1)} s$`));

    // 2x, then play: the file runs at twice the wall clock.
    r = await viewer();
    await page.selectOption('#replay-speed', '2');
    if (mock) await waitForReceived('{"type":"replay","speed":2}', (m) => m.type === 'replay' && m.speed === 2);
    await waitUntil(page, 'the server at 2x', (n) => window.duetViewer.replay.states > n && window.duetViewer.replay.state.speed === 2, r.states, 5);
    r = await viewer();
    await page.click('#replay-play');
    await waitUntil(page, 'the server playing', (n) => window.duetViewer.replay.states > n && window.duetViewer.replay.state.paused === false, r.states, 5);
    const a = await viewer();
    await waitUntil(page, 'a state 1.5 s later', (t0) => window.duetViewer.replay.received_ms - t0 >= 1500, a.received_ms, 5);
    const b = await viewer();
    const rate = (b.state.position_s - a.state.position_s) / ((b.received_ms - a.received_ms) / 1000);
    t.diagnostic(`replay ran ${rate.toFixed(2)} s of file per second at 2x`);
    assert.ok(rate > 1.4 && rate < 2.6, `at 2x the file ran ${rate.toFixed(2)} s per second`);

    // Back to 1x; frames keep coming.
    r = await viewer();
    await page.selectOption('#replay-speed', '1');
    await waitUntil(page, 'the server at 1x', (n) => window.duetViewer.replay.states > n && window.duetViewer.replay.state.speed === 1, r.states, 5);
    const frames = await page.evaluate(() => window.duetViewer.framesReceived);
    await waitUntil(page, 'frames after the replay test', (k) => window.duetViewer.framesReceived > k + 10, frames, 5);
  });

  test('Enter VR presents an emulated immersive session at the user head, then exits', async () => {
    requireFrames();
    const vr_page = await openViewer(urlWith(base_url, { 'xr-emulate': '1' }));
    try {
      await waitUntil(vr_page, 'frames on the VR page', () => window.duetViewer.framesReceived >= 10, null, 15);
      await waitUntil(vr_page, 'an enabled "Enter VR" button', () => {
        const b = document.getElementById('vr');
        return !b.disabled && b.textContent === 'Enter VR';
      }, null, 10);
      assert.equal(await vr_page.evaluate(() => window.duetViewer.xrEmulated), true);
      await vr_page.click('#vr');
      await waitUntil(vr_page, 'renderer.xr.isPresenting', () => window.duetViewer.xrPresenting, null, 10);
      const n0 = await vr_page.evaluate(() => window.duetViewer.renderCount);
      await waitUntil(vr_page, '10 renders while presenting', (n) => window.duetViewer.renderCount >= n + 10, n0, 10);
      const { rig, head, cam, mode } = await vr_page.evaluate(() => ({
        rig: window.duetViewer.rigWorld(),
        head: window.duetViewer.userHead(),
        cam: window.duetViewer.cameraWorld(),
        mode: window.duetViewer.cameraMode,
      }));
      assert.equal(mode, 'vr');
      // The rig stands under the user's head; the headset (local-floor) adds the eye height.
      assert.ok(Math.hypot(rig[0] - head[0], rig[2] - head[2]) < 0.01, `rig ${rig} is not under the head ${head}`);
      assert.ok(Math.hypot(cam[0] - head[0], cam[2] - head[2]) < 0.3, `VR camera ${cam} is far from the head ${head}`);
      mkdirSync(kResults, { recursive: true });
      await vr_page.screenshot({ path: path.join(kResults, 'vr.png') });
      if (mock) {
        // Advice in VR: the panel below the line of sight shows it while it lasts.
        mock.state.advice = { calibrate: { rig_offset: 0.094 } };
        await waitUntil(vr_page, 'the advice panel in VR', () => window.duetViewer.adviceHud.visible, null, 5);
        await vr_page.screenshot({ path: path.join(kResults, 'vr-advice.png') });
        mock.state.advice = null;
        await waitUntil(vr_page, 'the advice panel gone', () => !window.duetViewer.adviceHud.visible, null, 5);
      }
      await vr_page.click('#vr'); // "Exit VR", kept above the emulator's canvas
      await waitUntil(vr_page, 'the session to end', () => !window.duetViewer.xrPresenting, null, 10);
      assert.equal(await vr_page.evaluate(() => window.duetViewer.cameraMode), 'orbit');
      const n1 = await vr_page.evaluate(() => window.duetViewer.renderCount);
      await waitUntil(vr_page, 'renders after exiting VR', (n) => window.duetViewer.renderCount >= n + 5, n1, 5);
    } finally {
      await vr_page.close();
    }
  });
});
