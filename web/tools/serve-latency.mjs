// Connects to `duet serve` as a viewer and reports, once the server closes (e.g. a replay with
// --exit-at-end): per frame, `latency_us` of each frame message (arrival -> partner pose built);
// the last `stats` message's `latency_total_us` (arrival -> sent to this viewer, since the
// server started); reported jumps; and, given the replay's ground truth (`duet improvise
// --truth`), the share of frames within 100 ms of the true template frame.
// Usage: node web/tools/serve-latency.mjs ws://HOST:PORT/ws [TRUTH.csv LIBRARY_TAKE_INDEX]
import { readFileSync } from 'node:fs';
import WebSocket from 'ws';

const [url, truthPath, truthTake] = process.argv.slice(2);
if (!url || (truthPath && truthTake === undefined)) {
  console.error('usage: node web/tools/serve-latency.mjs ws://HOST:PORT/ws [TRUTH.csv TAKE]');
  process.exit(2);
}

// frame,time_s,take,template_frame,in_pause,jump -> rows by input frame
function readTruth(path) {
  const lines = readFileSync(path, 'utf8').trim().split('\n');
  const header = lines[0].split(',');
  const column = (name) => {
    const k = header.indexOf(name);
    if (k < 0) throw new Error(`${path}: no column ${name}`);
    return k;
  };
  const [timeK, frameK, pauseK] = [column('time_s'), column('template_frame'), column('in_pause')];
  return lines.slice(1).map((line) => {
    const cells = line.split(',');
    return { time: Number(cells[timeK]), frame: Number(cells[frameK]), pause: cells[pauseK] === '1' };
  });
}

const truth = truthPath ? readTruth(truthPath) : null;
const built = [];
let lastStats = null;
let frames = 0;
let jumps = 0;
let scored = 0;
let within = 0;
const socket = new WebSocket(url);
socket.on('message', (data) => {
  const message = JSON.parse(data.toString());
  if (message.type === 'frame') {
    frames += 1;
    if (typeof message.latency_us === 'number') built.push(message.latency_us);
    const follower = message.follower || {};
    if (follower.jumped) jumps += 1;
    if (truth) {
      // The replay's frames are at the truth's times; the nearest row is this frame's.
      const f = Math.round(message.time_s / (truth[1].time - truth[0].time));
      const row = truth[Math.min(truth.length - 1, Math.max(0, f))];
      if (row && !row.pause) {
        scored += 1;
        const take = Number(truthTake);
        // 100 ms at the template's 60 Hz: 6 frames.
        if (follower.take === take && Math.abs(follower.template_frame - row.frame) <= 6) within += 1;
      }
    }
  } else if (message.type === 'stats') {
    lastStats = message;
  }
});
socket.on('error', (error) => {
  console.error(`serve-latency: ${url}: ${error.message}`);
  process.exit(1);
});
socket.on('close', () => {
  built.sort((a, b) => a - b);
  const at = (p) => built[Math.min(built.length - 1, Math.floor((built.length * p) / 100))];
  const result = {
    frames,
    jumps,
    built_us: built.length ? { p50: at(50), p99: at(99), max: built[built.length - 1] } : null,
    sent_total_us: lastStats ? lastStats.latency_total_us : null,
  };
  if (truth) result.within_100ms = scored ? within / scored : null;
  console.log(JSON.stringify(result));
});
