// Timeline of the follower's template position (paper section 5): the current take over its
// length, where the follower is in it, its confidence, where it jumped, and the take's
// hand-contact intervals from `hello`.

const kHistoryFrames = 900; // confidence trail: the last 15 s at 60 Hz
const kMaxJumps = 64;
const kContactColors = { left: '#3fd0c9', right: '#ffc94d' };

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
    const x0 = 10;
    const x1 = w - 10;
    const plot_top = 26;
    const plot_bottom = h - 24;
    const lane_top = h - 20;
    const lane_h = 8;
    const x_of = (f) => x0 + (Math.min(Math.max(f, 0), frames) / frames) * (x1 - x0);
    const y_of = (c) => plot_bottom - c * (plot_bottom - plot_top);

    // Background, confidence grid lines at 0.5 and 1.
    ctx.fillStyle = 'rgba(255,255,255,0.04)';
    ctx.fillRect(x0, plot_top, x1 - x0, plot_bottom - plot_top);
    ctx.strokeStyle = 'rgba(255,255,255,0.10)';
    ctx.lineWidth = 1;
    for (const c of [0.5, 1]) {
      ctx.beginPath();
      ctx.moveTo(x0, Math.round(y_of(c)) + 0.5);
      ctx.lineTo(x1, Math.round(y_of(c)) + 0.5);
      ctx.stroke();
    }
    // Seconds ticks every 10 s of template time.
    ctx.fillStyle = 'rgba(255,255,255,0.25)';
    for (let s = 10; s * this.fps < frames; s += 10) {
      ctx.fillRect(Math.round(x_of(s * this.fps)), plot_bottom - 3, 1, 3);
    }

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
      ctx.arc(x, y_of(cur.confidence), 4, 0, 2 * Math.PI);
      ctx.fill();
    }
  }
}
