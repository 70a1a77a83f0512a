// WebXR: the "Enter VR" button, and an optional emulated headset for tests and desktops.
import * as THREE from 'three';

const kUp = new THREE.Vector3(0, 1, 0);

/**
 * Installs Meta's Immersive Web Emulation Runtime (an emulated Quest 3) as navigator.xr.
 * Called for `?xr-emulate=1` before the renderer exists; iwer is loaded only then.
 */
export async function installXREmulator() {
  const { XRDevice, metaQuest3 } = await import('iwer');
  const device = new XRDevice(metaQuest3);
  // Chromium may expose a native navigator.xr with no headset behind it; replace it.
  device.installRuntime({ forceInstall: true });
  return device;
}

/**
 * Drives `button` to start and end an immersive-vr session on `renderer` (renderer.xr.enabled
 * must be true). `onStart()` / `onEnd()` run when presenting starts and stops.
 */
export class VRSession {
  constructor(renderer, button, { onStart = () => {}, onEnd = () => {} } = {}) {
    this.renderer = renderer;
    this.button = button;
    this.onStart = onStart;
    this.onEnd = onEnd;
    this.session = null;
    this.supported = false;
    button.addEventListener('click', () => this.toggle());
  }

  /** Asks the browser whether immersive-vr is possible and labels the button accordingly. */
  async probe() {
    const xr = navigator.xr;
    let reason = 'VR not available';
    if (!xr) {
      reason = window.isSecureContext ? 'VR not available' : 'VR needs https or localhost';
    } else {
      try {
        this.supported = await xr.isSessionSupported('immersive-vr');
      } catch (err) {
        reason = `VR not allowed (${err.name})`;
      }
    }
    this.button.disabled = !this.supported;
    this.button.textContent = this.supported ? 'Enter VR' : reason;
    return this.supported;
  }

  async toggle() {
    if (this.session) {
      await this.session.end();
      return;
    }
    if (!this.supported) return;
    this.button.disabled = true;
    try {
      const session = await navigator.xr.requestSession('immersive-vr', {
        optionalFeatures: ['local-floor'],
      });
      session.addEventListener('end', () => {
        this.session = null;
        this.button.textContent = 'Enter VR';
        this.onEnd();
      });
      await this.renderer.xr.setSession(session);
      this.session = session;
      this.button.textContent = 'Exit VR';
      this.onStart();
    } catch (err) {
      this.button.textContent = `VR failed: ${err.message}`;
      console.error('duet viewer: cannot start VR', err);
    } finally {
      this.button.disabled = !this.supported;
    }
  }
}

/**
 * Places `rig` (the camera's parent) so the headset stands where the user's head is and looks
 * where the user faces: the floor under `head_ws`, turned so the rig's -Z is `facing_ws`.
 * The 'local-floor' space adds the wearer's own eye height and head motion on top.
 */
export function placeRigAtHead(rig, head_ws, facing_ws) {
  rig.position.set(head_ws.x, 0, head_ws.z);
  rig.quaternion.setFromAxisAngle(kUp, Math.atan2(-facing_ws.x, -facing_ws.z));
}
