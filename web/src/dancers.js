// Stick-figure dancers built from the skeletons in `hello` and posed by each `frame`.
import * as THREE from 'three';

/** Colours by dance role, as in the paper's figure 2: leader blue, partner pink. */
export const kRoleColors = { leader: 0x2f6fff, partner: 0xff4fa3 };

const kBoneRadius_m = 0.028;
const kJointRadius_m = 0.04;
const kHeadRadius_m = 0.1;
const kMinBoneLength_m = 1e-3;
const kHandMarker_m = [0.05, 0.04, 0.12]; // width, height, length of a controller-like hand // zero-length bones (coincident joints) get no cylinder

// Joint names per role in the conventions of docs/skeleton-maps.md (daz, cmu-bvh, cmu-asf),
// plus common spellings of other rigs; matched case-insensitively.
const kRoleNames = {
  head: ['head', 'Head'],
  left_hip: ['lThigh', 'LeftUpLeg', 'lfemur', 'LeftHip', 'l_hip', 'LeftThigh'],
  right_hip: ['rThigh', 'RightUpLeg', 'rfemur', 'RightHip', 'r_hip', 'RightThigh'],
  left_shoulder: ['lShldr', 'LeftArm', 'lhumerus', 'LeftShoulder', 'l_shoulder', 'LeftUpperArm'],
  right_shoulder: ['rShldr', 'RightArm', 'rhumerus', 'RightShoulder', 'r_shoulder', 'RightUpperArm'],
  left_wrist: ['lHand', 'LeftHand', 'lwrist', 'l_wrist', 'LeftWrist'],
  right_wrist: ['rHand', 'RightHand', 'rwrist', 'r_wrist', 'RightWrist'],
};

/** Index of the joint playing `role` in `joints` ([{name, parent}]), or -1. */
export function findRoleJoint(joints, role) {
  const wanted = kRoleNames[role].map((n) => n.toLowerCase());
  for (const name of wanted) {
    const i = joints.findIndex((j) => String(j.name).toLowerCase() === name);
    if (i >= 0) return i;
  }
  return -1;
}

const kUp = new THREE.Vector3(0, 1, 0);
const kBoneAxis = new THREE.Vector3(0, 1, 0); // the unit cylinder spans y in [0, 1]

/**
 * One dancer: a sphere per joint, a cylinder per bone (joint -> parent), a bigger head; or, for
 * a head-and-hands skeleton (a headset user), a head sphere and two hand blocks only.
 * Owns its meshes under `this.group`; `dispose()` frees them.
 */
export class StickFigure {
  /**
   * @param skeleton {joints: [{name, parent}]} from `hello`; parents precede children or not,
   *   either works (positions come in world space).
   * @param color  three.js colour of the dance role.
   */
  constructor(skeleton, color) {
    const joints = Array.isArray(skeleton?.joints) ? skeleton.joints : [];
    this.joints = joints.map((j) => ({
      name: String(j.name ?? ''),
      parent: Number.isInteger(j.parent) ? j.parent : -1,
    }));
    this.group = new THREE.Group();
    this.material = new THREE.MeshStandardMaterial({ color, roughness: 0.55, metalness: 0.05 });
    // Roles by joint name first (as before), then the server's `roles` for what names missed.
    const given = skeleton?.roles && typeof skeleton.roles === 'object' ? skeleton.roles : {};
    const index = (i) => (Number.isInteger(i) && i >= 0 && i < this.joints.length ? i : -1);
    this.roles = {};
    for (const role of Object.keys(kRoleNames)) {
      const found = findRoleJoint(this.joints, role);
      this.roles[role] = found >= 0 ? found : index(given[role]);
    }
    this.roles.hips = index(given.hips);
    /** A head and two hands only (a VR headset and its controllers): no bones are drawn. */
    this.pointsOnly = this.roles.head >= 0 && this.roles.left_wrist >= 0 &&
      this.roles.right_wrist >= 0 && this.roles.hips < 0 && this.roles.left_hip < 0;

    const joint_geo = new THREE.SphereGeometry(kJointRadius_m, 12, 8);
    const head_geo = new THREE.SphereGeometry(kHeadRadius_m, 20, 14);
    const bone_geo = new THREE.CylinderGeometry(kBoneRadius_m, kBoneRadius_m, 1, 10, 1);
    bone_geo.translate(0, 0.5, 0);
    // A hand of a points-only figure: a controller-sized block, long along its -Z (pointing).
    const hand_geo = new THREE.BoxGeometry(kHandMarker_m[0], kHandMarker_m[1], kHandMarker_m[2]);
    this.geometries_ = [joint_geo, head_geo, bone_geo, hand_geo];

    const hands = [this.roles.left_wrist, this.roles.right_wrist];
    // Which joints are drawn at all: every one, or for a points-only figure the head and hands.
    this.shown_ = this.joints.map((_, i) => !this.pointsOnly || i === this.roles.head || hands.includes(i));
    this.jointMeshes = this.joints.map((_, i) => {
      let geo = joint_geo;
      if (i === this.roles.head) geo = head_geo;
      else if (this.pointsOnly && hands.includes(i)) geo = hand_geo;
      const mesh = new THREE.Mesh(geo, this.material);
      mesh.visible = false; // until the first frame places it
      this.group.add(mesh);
      return mesh;
    });
    this.boneMeshes = this.joints.map((j) => {
      if (this.pointsOnly || j.parent < 0 || j.parent >= this.joints.length) return null;
      const mesh = new THREE.Mesh(bone_geo, this.material);
      mesh.visible = false;
      this.group.add(mesh);
      return mesh;
    });
    /** World positions of the last frame applied, one Vector3 per joint. */
    this.positions_ws = this.joints.map(() => new THREE.Vector3());
    /** World rotations of the last frame applied. */
    this.rotations_ws = this.joints.map(() => new THREE.Quaternion());
    this.posed = false;
    this.headHidden_ = false;
    this.gripOffset_m_ = 0;
  }

  /**
   * A headset user's devices, as `hello.device_offsets` gives them: the server moved each
   * controller's grip `grip_m` along its +Y (WebXR's grip space, toward the arm) to the wrist;
   * the hand blocks are drawn back at the grips, where the controllers are.
   */
  setDeviceOffsets(offsets) {
    const grip = Number(offsets?.grip_m);
    this.gripOffset_m_ = this.pointsOnly && Number.isFinite(grip) ? grip : 0;
  }

  setColor(color) {
    this.material.color.set(color);
  }

  /** Hides the head sphere (first-person and VR views sit inside it). */
  setHeadHidden(hidden) {
    this.headHidden_ = hidden;
    const head = this.roles.head;
    if (head >= 0 && this.posed) this.jointMeshes[head].visible = !hidden;
  }

  /**
   * Poses the figure from a frame's dancer: {positions: [[x,y,z]], rotations: [[w,x,y,z]]}.
   * Joints missing from the arrays (or malformed) keep their last transform.
   */
  applyPose(pose) {
    const positions = Array.isArray(pose?.positions) ? pose.positions : [];
    const rotations = Array.isArray(pose?.rotations) ? pose.rotations : [];
    const n = this.joints.length;
    for (let i = 0; i < n; ++i) {
      const p = positions[i];
      if (Array.isArray(p) && p.length >= 3) this.positions_ws[i].set(+p[0], +p[1], +p[2]);
      const q = rotations[i];
      if (Array.isArray(q) && q.length >= 4) this.rotations_ws[i].set(+q[1], +q[2], +q[3], +q[0]); // [w,x,y,z]
    }
    for (let i = 0; i < n; ++i) {
      const joint = this.jointMeshes[i];
      joint.position.copy(this.positions_ws[i]);
      joint.quaternion.copy(this.rotations_ws[i]);
      joint.visible = this.shown_[i] && !(this.headHidden_ && i === this.roles.head);
      if (this.gripOffset_m_ !== 0 && (i === this.roles.left_wrist || i === this.roles.right_wrist)) {
        const to_arm = joint.userData.toArm ?? (joint.userData.toArm = new THREE.Vector3());
        joint.position.addScaledVector(to_arm.set(0, 1, 0).applyQuaternion(this.rotations_ws[i]), -this.gripOffset_m_);
      }
      const bone = this.boneMeshes[i];
      if (!bone) continue;
      const from = this.positions_ws[this.joints[i].parent];
      const dir = bone.userData.dir ?? (bone.userData.dir = new THREE.Vector3());
      dir.subVectors(this.positions_ws[i], from);
      const length = dir.length();
      if (!(length > kMinBoneLength_m)) {
        bone.visible = false;
        continue;
      }
      bone.visible = true;
      bone.position.copy(from);
      bone.quaternion.setFromUnitVectors(kBoneAxis, dir.divideScalar(length));
      bone.scale.set(1, length, 1);
    }
    this.posed = true;
  }

  /** World position of the head joint (or the highest joint if none is named head). */
  headPosition(out = new THREE.Vector3()) {
    let head = this.roles.head;
    if (head < 0) {
      head = 0;
      this.positions_ws.forEach((p, i) => {
        if (p.y > this.positions_ws[head].y) head = i;
      });
    }
    return out.copy(this.positions_ws[head] ?? out.set(0, 1.6, 0));
  }

  /**
   * Horizontal unit vector the dancer faces: up x (right - left) over hips and shoulders,
   * falling back to the head joint's +Z when the skeleton has no named sides; a points-only
   * figure faces where its headset looks.
   */
  facing(out = new THREE.Vector3()) {
    if (this.pointsOnly) {
      // A headset's orientation looks along its -Z (WebXR's convention, docs/protocol.md).
      out.set(0, 0, -1).applyQuaternion(this.rotations_ws[this.roles.head]);
      out.y = 0;
      if (out.lengthSq() < 1e-8) out.set(0, 0, -1);
      return out.normalize();
    }
    const side = new THREE.Vector3();
    const r = this.roles;
    for (const [left, right] of [
      [r.left_hip, r.right_hip],
      [r.left_shoulder, r.right_shoulder],
    ]) {
      if (left >= 0 && right >= 0) side.add(this.positions_ws[right]).sub(this.positions_ws[left]);
    }
    out.crossVectors(kUp, side);
    out.y = 0;
    if (out.lengthSq() < 1e-8) {
      const head = r.head >= 0 ? r.head : 0;
      out.set(0, 0, 1).applyQuaternion(this.rotations_ws[head] ?? new THREE.Quaternion());
      out.y = 0;
      if (out.lengthSq() < 1e-8) out.set(0, 0, 1);
    }
    return out.normalize();
  }

  dispose() {
    this.group.removeFromParent();
    this.geometries_.forEach((g) => g.dispose());
    this.material.dispose();
  }
}
