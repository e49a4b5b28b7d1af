// The TF layer: axes (x red, y green, z blue) and the name of every frame TF can place in the fixed frame.
import * as THREE from './three.js';
import { disposeTree, textSprite } from './labels.js';

export class TfAxes {
  constructor(parent) {
    this.group = new THREE.Group();
    this.group.name = 'tf';
    parent.add(this.group);
    this.items = new Map();
  }

  item(name) {
    let item = this.items.get(name);
    if (!item) {
      item = new THREE.Group();
      item.matrixAutoUpdate = false;
      item.add(new THREE.AxesHelper(0.3));
      const label = textSprite(name, { height: 0.08 });
      label.position.set(0, 0, 0.08);
      item.add(label);
      this.group.add(item);
      this.items.set(name, item);
    }
    return item;
  }

  place(poses) {
    const fixedInverse = poses.fixedInverse();
    const seen = new Set();
    for (const name of Object.keys(poses.frames)) {
      const m = poses.inFixed(name, fixedInverse);
      if (!m) continue;
      const item = this.item(name);
      item.matrix.copy(m);
      item.matrixWorldNeedsUpdate = true;
      seen.add(name);
    }
    for (const [name, item] of this.items) {
      if (!seen.has(name)) { this.group.remove(item); disposeTree(item); this.items.delete(name); }
    }
  }
}
