// Timeline of the follower's template position (paper section 5): the current take over its
// length, where the follower is in it, its confidence, where it jumped, and the take's
// hand-contact intervals from `hello`.

const kHistoryFrames = 900; // confidence trail: the last 15 s at 60 Hz
const kMaxJumps = 64;
const kContactColors = { left: '#3fd0c9', right: '#ffc94d' };
const kCursorRadius = 4; // the current confidence's dot
const kTickSteps_s = [1, 2, 5, 10, 15, 30, 60, 120, 300, 600];
const kMinTickSpacing_px = 56;

/** "7 s" under a minute, else "1:05". */
function timeLabel(seconds, long) {
  if (!long) return `${seconds} s`;
  const m = Math.floor(seconds / 60);
  const s = seconds % 60;
  return `${m}:${String(s).padStart(2, '0')}`;
}

export class Timeline {
  /** @param canvas a <canvas> sized by CSS; the drawing follows its size and the pixel ratio. */
  constructor(canvas) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.takes = [];
    this.fps = 60;
    this.clear();
    this.dirty_ = true;
  }

  /** New `hello`: takes [{name, frames, contacts}] and the template frame rate. */
  setTakes(takes, fps) {
    this.takes = Array.isArray(takes) ? takes : [];
    this.fps = fps > 0 ? fps : 60;
    this.clear();
  }

  /** Forgets the trail and the jumps (after a reset or a new hello). */
  clear() {
    this.history = [];
    this.jumps = [];
    this.current = null;
    this.dirty_ = true;
  }

  /** Adds one frame's `follower` block. */
  push(follower) {
    if (!follower || typeof follower !== 'object') return;
    const entry = {
      take: Number.isInteger(follower.take) ? follower.take : 0,
      frame: Number(follower.template_frame) || 0,
      confidence: Math.min(1, Math.max(0, Number(follower.confidence) || 0)),
      lost: !!follower.lost,
      in_pause: !!follower.in_pause,
    };
    const previous = this.current;
    if (follower.jumped) {
      this.jumps.push({ take: entry.take, to: entry.frame, from: previous?.frame, fromTake: previous?.take });
      if (this.jumps.length > kMaxJumps) this.jumps.shift();
    }
    this.history.push(entry);
    if (this.history.length > kHistoryFrames) this.history.splice(0, this.history.length - kHistoryFrames);
    this.current = entry;
    this.dirty_ = true;
  }

  /** Geometry of the track for a canvas `w` x `h` CSS pixels and a take of `frames` frames:
   *  the plot's edges, where confidence 1 and 0 sit (inset by the cursor's radius, so a dot at
   *  either end is whole), and the labelled time ticks. */
  layout(w, h, frames) {
    const x0 = 10;
    const x1 = w - 10;
    const plot_top = 26;
    const plot_bottom = h - 40;
    const inset = kCursorRadius + 1;
    const y_of = (c) => plot_bottom - inset - c * (plot_bottom - plot_top - 2 * inset);
    const x_of = (f) => x0 + (Math.min(Math.max(f, 0), frames) / frames) * (x1 - x0);
    const duration_s = frames / this.fps;
    const px_per_s = (x1 - x0) / Math.max(duration_s, 1e-6);
    const step = kTickSteps_s.find((st) => st * px_per_s >= kMinTickSpacing_px) ?? kTickSteps_s.at(-1);
    const ticks = [];
    for (let sec = 0; sec <= duration_s + 1e-9; sec += step) {
      ticks.push({ seconds: sec, label: timeLabel(sec, duration_s >= 60), x: x_of(sec * this.fps) });
    }
    return {
      x0, x1, plotTop: plot_top, plotBottom: plot_bottom, labelTop: plot_bottom + 5,
      laneTop: h - 22, laneHeight: 8, yOne: y_of(1), yZero: y_of(0), dotRadius: kCursorRadius,
      ticks, x_of, y_of,
    };
  }

  /** Redraws if anything changed since the last call (or the canvas was resized). */
  draw() {
    const canvas = this.canvas;
    const ratio = window.devicePixelRatio || 1;
    const width = Math.max(1, Math.round(canvas.clientWidth * ratio));
    const height = Math.max(1, Math.round(canvas.clientHeight * ratio));
    if (canvas.width !== width || canvas.height !== height) {
      canvas.width = width;
      canvas.height = height;
      this.dirty_ = true;
    }
    if (!this.dirty_) return;
    this.dirty_ = false;

    const ctx = this.ctx;
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    const w = canvas.clientWidth;
    const h = canvas.clientHeight;
    ctx.clearRect(0, 0, w, h);
    ctx.font = '12px system-ui, sans-serif';
    ctx.textBaseline = 'top';

    const cur = this.current;
    const take = cur ? this.takes[cur.take] : this.takes[0];
    const take_index = cur ? cur.take : 0;
    const frames = Math.max(1, Number(take?.frames) || 1);

    // Header.
    ctx.fillStyle = '#e6e8ee';
    let header = 'waiting for frames';
    if (cur) {
      const name = take ? `"${take.name}"` : '(unknown take)';
      header =
        `take ${cur.take} ${name}   frame ${cur.frame} / ${frames}` +
        `   (${(cur.frame / this.fps).toFixed(1)} s)   confidence ${cur.confidence.toFixed(2)}` +
        (cur.lost ? '   LOST' : '') +
        (cur.in_pause ? '   pause' : '');
    }
    ctx.fillText(header, 10, 6);
    const legend = [
      ['jump ', '#9aa1b1'],
      ['▼', '#ff5a5a'],
      ['   contact: user right hand ', '#9aa1b1'],
      ['■', kContactColors.right],
      ['  left hand ', '#9aa1b1'],
      ['■', kContactColors.left],
    ];
    let lx = w - 10 - legend.reduce((sum, [text]) => sum + ctx.measureText(text).width, 0);
    for (const [text, color] of legend) {
      ctx.fillStyle = color;
      ctx.fillText(text, lx, 6);
      lx += ctx.measureText(text).width;
    }

    // Geometry of the track.
    const L = this.layout(w, h, frames);
    this.lastLayout = L;
    const { x0, x1, x_of, y_of } = L;
    const plot_top = L.plotTop;
    const plot_bottom = L.plotBottom;
    const lane_top = L.laneTop;
    const lane_h = L.laneHeight;

    // Background, confidence grid lines at 0, 0.5 and 1 with their values at the right end.
    ctx.fillStyle = 'rgba(255,255,255,0.04)';
    ctx.fillRect(x0, plot_top, x1 - x0, plot_bottom - plot_top);
    ctx.strokeStyle = 'rgba(255,255,255,0.10)';
    ctx.lineWidth = 1;
    for (const c of [0, 0.5, 1]) {
      ctx.beginPath();
      ctx.moveTo(x0, Math.round(y_of(c)) + 0.5);
      ctx.lineTo(x1, Math.round(y_of(c)) + 0.5);
      ctx.stroke();
    }
    ctx.font = '10px system-ui, sans-serif';
    ctx.textBaseline = 'middle';
    ctx.textAlign = 'right';
    ctx.fillStyle = 'rgba(255,255,255,0.35)';
    for (const c of [0, 1]) ctx.fillText(String(c), x1 - 2, y_of(c));
    // Time ticks of the template, labelled under the plot, with faint lines across it.
    ctx.textBaseline = 'top';
    ctx.textAlign = 'center';
    for (const t of L.ticks) {
      const x = Math.round(t.x) + 0.5;
      ctx.strokeStyle = 'rgba(255,255,255,0.06)';
      ctx.beginPath();
      ctx.moveTo(x, plot_top);
      ctx.lineTo(x, plot_bottom);
      ctx.stroke();
      ctx.strokeStyle = 'rgba(255,255,255,0.45)';
      ctx.beginPath();
      ctx.moveTo(x, plot_bottom);
      ctx.lineTo(x, plot_bottom + 4);
      ctx.stroke();
      ctx.fillStyle = '#9aa1b1';
      // The first and last labels stay inside the canvas.
      const half = ctx.measureText(t.label).width / 2;
      ctx.fillText(t.label, Math.min(Math.max(t.x, half + 1), w - half - 1), L.labelTop);
    }
    ctx.textAlign = 'left';
    ctx.font = '12px system-ui, sans-serif';

    // Hand-contact intervals [start, end) of this take.
    const contacts = Array.isArray(take?.contacts) ? take.contacts : [];
    ctx.fillStyle = 'rgba(255,255,255,0.06)';
    ctx.fillRect(x0, lane_top, x1 - x0, 2 * lane_h + 2);
    for (const c of contacts) {
      const hand = c.user_hand === 'left' ? 'left' : 'right';
      const y = lane_top + (hand === 'right' ? 0 : lane_h + 2);
      const xs = x_of(Number(c.start) || 0);
      const xe = x_of(Number(c.end) || 0);
      ctx.fillStyle = kContactColors[hand];
      ctx.fillRect(xs, y, Math.max(1, xe - xs), lane_h);
    }

    // Confidence trail of this take, older points fainter.
    const trail = this.history;
    for (let i = 0; i < trail.length; ++i) {
      const e = trail[i];
      if (e.take !== take_index) continue;
      const age = (trail.length - 1 - i) / kHistoryFrames;
      ctx.globalAlpha = 0.15 + 0.85 * (1 - age);
      ctx.fillStyle = e.lost ? '#ff7a6b' : '#c8d0e0';
      ctx.fillRect(x_of(e.frame) - 1, y_of(e.confidence) - 1, 2, 2);
    }
    ctx.globalAlpha = 1;

    // Jumps landing in this take.
    ctx.fillStyle = '#ff5a5a';
    ctx.strokeStyle = 'rgba(255,90,90,0.6)';
    for (const j of this.jumps) {
      if (j.take !== take_index) continue;
      const x = x_of(j.to);
      ctx.beginPath();
      ctx.moveTo(x - 4, plot_top - 6);
      ctx.lineTo(x + 4, plot_top - 6);
      ctx.lineTo(x, plot_top);
      ctx.closePath();
      ctx.fill();
      ctx.beginPath();
      ctx.moveTo(Math.round(x) + 0.5, plot_top);
      ctx.lineTo(Math.round(x) + 0.5, plot_bottom);
      ctx.stroke();
    }

    // Cursor at the current template frame.
    if (cur) {
      const x = Math.round(x_of(cur.frame)) + 0.5;
      ctx.strokeStyle = '#ffffff';
      ctx.lineWidth = 2;
      ctx.beginPath();
      ctx.moveTo(x, plot_top);
      ctx.lineTo(x, lane_top + 2 * lane_h + 2);
      ctx.stroke();
      ctx.fillStyle = '#ffffff';
      ctx.beginPath();
      ctx.arc(x, y_of(cur.confidence), kCursorRadius, 0, 2 * Math.PI);
      ctx.fill();
    }
  }
}
