// TF poses from the `view3d` channel: every frame's [x, y, z, qx, qy, qz, qw] in the robot's base frame.
// The viewer's world is the fixed frame the operator chose; a frame's pose in it is
// inverse(T_base_fixed) * T_base_frame, composed here so the server computes one set for every viewer.
import * as THREE from './three.js';

export function matrixOf(pose) {
  const m = new THREE.Matrix4();
  m.compose(new THREE.Vector3(pose[0], pose[1], pose[2]),
    new THREE.Quaternion(pose[3], pose[4], pose[5], pose[6]), new THREE.Vector3(1, 1, 1));
  return m;
}

export class Poses {
  constructor() {
    this.frames = {};      // name -> pose in base, or null
    this.base = 'base_link';
    this.fixed = 'base_link';
    this.aliases = {};     // the card's 'map' and 'odom': the robot's own names for them (settings)
  }

  update(message) {
    this.base = message.base || this.base;
    this.frames = message.frames || {};
  }

  // The fixed frame as the operator chose it; 'robot' is the base frame.
  fixedName() { return this.fixed === 'robot' ? this.base : (this.aliases[this.fixed] || this.fixed); }

  // inverse(T_base_fixed), or null while TF does not connect the fixed frame to the base.
  fixedInverse() {
    const name = this.fixedName();
    if (name === this.base) return new THREE.Matrix4();
    const pose = this.frames[name];
    return pose ? matrixOf(pose).invert() : null;
  }

  // A frame's matrix in the fixed frame, or null when TF cannot place it.
  inFixed(frame, fixedInverse = this.fixedInverse()) {
    if (!fixedInverse) return null;
    const name = frame.replace(/^\//, '') || this.base;
    const pose = name === this.base ? [0, 0, 0, 0, 0, 0, 1] : this.frames[name];
    return pose ? fixedInverse.clone().multiply(matrixOf(pose)) : null;
  }
}
