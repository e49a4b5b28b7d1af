// visualization_msgs markers in 3D (the `view3d_markers` channel): each in its own frame, placed through TF
// at its stamp.
import * as THREE from './three.js';
import { disposeTree, textSprite } from './labels.js';
import { matrixOf } from './poses.js';

const v3 = (p) => new THREE.Vector3(p[0], p[1], p[2]);

function material(color, kind = 'mesh') {
  const [r, g, b, a] = color;
  const common = { color: new THREE.Color(r, g, b), transparent: a < 1, opacity: a };
  if (kind === 'line') return new THREE.LineBasicMaterial(common);
  if (kind === 'points') return new THREE.PointsMaterial({ ...common, size: 4, sizeAttenuation: false });
  return new THREE.MeshLambertMaterial(common);
}

function instanced(geometry, m, points, scale) {
  const mesh = new THREE.InstancedMesh(geometry, material(m.color), points.length);
  const matrix = new THREE.Matrix4();
  points.forEach((p, i) => {
    matrix.compose(v3(p), new THREE.Quaternion(), new THREE.Vector3(scale[0], scale[1], scale[2]));
    mesh.setMatrixAt(i, matrix);
    if (m.colors[i]) mesh.setColorAt(i, new THREE.Color(m.colors[i][0], m.colors[i][1], m.colors[i][2]));
  });
  return mesh;
}

function lineGeometry(points) {
  return new THREE.BufferGeometry().setFromPoints(points.map(v3));
}

// One marker's drawing, in its own pose (the pose is applied by the caller).
export function build(m, meshBase) {
  const s = m.scale;
  switch (m.kind) {
    case 'arrow': {
      if (m.points.length >= 2) {  // from points[0] to points[1]: shaft diameter, head diameter, head length
        const from = v3(m.points[0]);
        const dir = v3(m.points[1]).sub(from);
        const length = dir.length();
        const arrow = new THREE.ArrowHelper(dir.normalize(), from, length, 0, Math.min(s[2] || length * 0.3, length),
          s[1] || 0.05);
        arrow.setColor(new THREE.Color(m.color[0], m.color[1], m.color[2]));
        return arrow;
      }
      const arrow = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), s[0], 0,
        s[0] * 0.3, Math.max(s[1], s[2]) * 2);
      arrow.setColor(new THREE.Color(m.color[0], m.color[1], m.color[2]));
      return arrow;
    }
    case 'cube': return new THREE.Mesh(new THREE.BoxGeometry(s[0], s[1], s[2]), material(m.color));
    case 'sphere': {
      const mesh = new THREE.Mesh(new THREE.SphereGeometry(0.5, 16, 12), material(m.color));
      mesh.scale.set(s[0], s[1], s[2]);
      return mesh;
    }
    case 'cylinder': {  // ROS's cylinder stands on z; three's on y
      const mesh = new THREE.Mesh(new THREE.CylinderGeometry(0.5, 0.5, 1, 20), material(m.color));
      mesh.rotation.x = Math.PI / 2;
      const g = new THREE.Group();
      g.add(mesh);
      g.scale.set(s[0], s[1], s[2]);
      return g;
    }
    case 'line_strip': return new THREE.Line(lineGeometry(m.points), material(m.color, 'line'));
    case 'line_list': return new THREE.LineSegments(lineGeometry(m.points), material(m.color, 'line'));
    case 'cube_list': return instanced(new THREE.BoxGeometry(1, 1, 1), m, m.points, s);
    case 'sphere_list': return instanced(new THREE.SphereGeometry(0.5, 12, 8), m, m.points, s);
    case 'points': {
      const geometry = lineGeometry(m.points);
      const points = new THREE.Points(geometry, material(m.color, 'points'));
      points.material.size = Math.max(2, s[0] * 100);
      return points;
    }
    case 'text': {
      const c = m.color;
      return textSprite(m.text, { height: s[2] || 0.2,
        color: `rgb(${Math.round(c[0] * 255)},${Math.round(c[1] * 255)},${Math.round(c[2] * 255)})` });
    }
    case 'triangle_list': {
      const geometry = lineGeometry(m.points);
      geometry.computeVertexNormals();
      const mat = material(m.color);
      mat.side = THREE.DoubleSide;
      return new THREE.Mesh(geometry, mat);
    }
    case 'mesh': {
      const g = new THREE.Group();
      const found = /^package:\/\/([^/]+)\/(.+)$/.exec(m.mesh || '');
      const kind = (m.mesh?.match(/\.(\w+)$/) || [])[1]?.toLowerCase();
      if (found && kind === 'stl') {
        new THREE.STLLoader().load(`${meshBase}/${encodeURIComponent(found[1])}/${found[2]}`,
          (geometry) => g.add(new THREE.Mesh(geometry, material(m.color))));
      } else if (found && kind === 'dae') {
        new THREE.ColladaLoader().load(`${meshBase}/${encodeURIComponent(found[1])}/${found[2]}`,
          (dae) => g.add(dae.scene));
      } else if (found && kind === 'obj') {
        new THREE.OBJLoader().load(`${meshBase}/${encodeURIComponent(found[1])}/${found[2]}`, (obj) => g.add(obj));
      }
      g.scale.set(s[0] || 1, s[1] || 1, s[2] || 1);
      return g;
    }
    default: return null;
  }
}

export class MarkerLayer {
  constructor(parent, meshBase) {
    this.group = new THREE.Group();
    this.group.name = 'markers';
    parent.add(this.group);
    this.meshBase = meshBase;
    this.items = [];
  }

  set(markers) {
    for (const item of this.items) { this.group.remove(item.holder); disposeTree(item.holder); }
    this.items = [];
    for (const m of markers) {
      const drawing = build(m, this.meshBase);
      if (!drawing) continue;
      const pose = new THREE.Group();  // the marker's own pose in its frame
      pose.position.set(m.pose[0], m.pose[1], m.pose[2]);
      pose.quaternion.set(m.pose[3], m.pose[4], m.pose[5], m.pose[6]);
      if (pose.quaternion.lengthSq() === 0) pose.quaternion.identity();
      pose.add(drawing);
      const holder = new THREE.Group();  // its frame in the fixed frame
      holder.matrixAutoUpdate = false;
      holder.add(pose);
      holder.userData = { ns: m.ns, id: m.id, kind: m.kind };
      this.group.add(holder);
      this.items.push({ holder, frame: m.frame_id, atStamp: m.at_stamp || null });
    }
  }

  // As tf2 and RViz place a marker: where its frame was at its stamp (at_stamp, from the server); a marker
  // stamped 0 or frame_locked follows its frame's latest pose. One the server placed at its stamp but not
  // in this fixed frame (TF could not join them then) is not drawn.
  place(poses) {
    const fixedInverse = poses.fixedInverse();
    for (const { holder, frame, atStamp } of this.items) {
      const stamped = atStamp?.[poses.fixedName()];
      const m = atStamp ? (stamped ? matrixOf(stamped) : null)
        : poses.inFixed(frame || poses.fixedName(), fixedInverse);
      holder.visible = Boolean(m);
      if (m) { holder.matrix.copy(m); holder.matrixWorldNeedsUpdate = true; }
    }
  }
}
