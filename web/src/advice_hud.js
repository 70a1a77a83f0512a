// The server's advice (advice.js) in VR, where the status panel cannot be seen: a panel of text
// hanging below the line of sight, carried by the camera, shown only while presenting and while
// there is advice. Drawn into a canvas only when the text changes.
import * as THREE from 'three';

const kCanvas = { width: 1024, height: 320 };
const kPanel_m = { width: 1.0, height: 0.3125 }; // at kDistance_m: about 45 x 15 degrees of view
const kDistance_m = 1.2;
const kBelow_m = 0.45; // about 20 degrees below the line of sight, so the dance stays in view
const kFont_px = 40; // about 2 degrees high: readable in a headset
const kMargin_px = 24;

/** Splits `text` into lines no wider than `width` as `measure(line)` reports. */
export function wrapLines(text, width, measure) {
  const lines = [];
  let line = '';
  for (const word of text.split(/\s+/).filter(Boolean)) {
    const candidate = line ? `${line} ${word}` : word;
    if (line && measure(candidate) > width) {
      lines.push(line);
      line = word;
    } else {
      line = candidate;
    }
  }
  if (line) lines.push(line);
  return lines;
}

export class AdviceHud {
  constructor(camera) {
    this.canvas = document.createElement('canvas');
    this.canvas.width = kCanvas.width;
    this.canvas.height = kCanvas.height;
    this.texture = new THREE.CanvasTexture(this.canvas);
    this.texture.colorSpace = THREE.SRGBColorSpace;
    const material = new THREE.MeshBasicMaterial({ map: this.texture, transparent: true, depthTest: false });
    this.mesh = new THREE.Mesh(new THREE.PlaneGeometry(kPanel_m.width, kPanel_m.height), material);
    this.mesh.position.set(0, -kBelow_m, -kDistance_m);
    this.mesh.renderOrder = 1000; // over the dancers
    this.mesh.visible = false;
    camera.add(this.mesh);
    this.text = '';
  }

  /** Shows `text` ('' for none) while `presenting` (in VR). */
  show(text, presenting) {
    if (text !== this.text) {
      this.text = text;
      this.draw();
    }
    this.mesh.visible = presenting && !!text;
  }

  get visible() { return this.mesh.visible; }

  draw() {
    const ctx = this.canvas.getContext('2d');
    ctx.clearRect(0, 0, kCanvas.width, kCanvas.height);
    if (!this.text) return;
    ctx.fillStyle = 'rgba(20, 24, 32, 0.85)';
    ctx.fillRect(0, 0, kCanvas.width, kCanvas.height);
    ctx.fillStyle = '#9fd3ff';
    ctx.font = `${kFont_px}px sans-serif`;
    ctx.textBaseline = 'top';
    const lines = wrapLines(this.text, kCanvas.width - 2 * kMargin_px, (s) => ctx.measureText(s).width);
    const step = kFont_px * 1.2;
    const fit = Math.max(1, Math.floor((kCanvas.height - 2 * kMargin_px) / step));
    lines.slice(0, fit).forEach((line, i) => ctx.fillText(line, kMargin_px, kMargin_px + i * step));
    this.texture.needsUpdate = true;
  }
}
