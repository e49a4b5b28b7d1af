// What LiveMap's overlays already send, drawn in 3D from the same subscriptions on the server: the laser
// scan (its own `scan3d` channel: the same returns with heights), costmaps and the live occupancy grid as
// textured ground planes, and the Nav2 plan, all in the map frame; the GPS track in local east-north-up metres around its first fix.
import * as THREE from './three.js';
import { at } from '../core/api.js';
import { on } from '../live/live.js';
import { renderCostmap } from '../livemap/layers/costmap.js';
import { disposeTree } from './labels.js';

const EARTH_M = 6378137;

function groundPlane(texture, width, height, origin, z) {
  const [ox, oy, oyaw = 0] = origin;
  const mesh = new THREE.Mesh(new THREE.PlaneGeometry(width, height),
    new THREE.MeshBasicMaterial({ map: texture, transparent: true, depthWrite: false, side: THREE.DoubleSide }));
  // the plane's centre, turned with the grid about its origin corner
  const c = Math.cos(oyaw), s = Math.sin(oyaw);
  mesh.position.set(ox + c * width / 2 - s * height / 2, oy + s * width / 2 + c * height / 2, z);
  mesh.rotation.z = oyaw;
  return mesh;
}

export class Overlays {
  constructor(parent, requestDraw) {
    this.requestDraw = requestDraw;
    this.map = new THREE.Group();   // everything given in the map frame
    this.map.matrixAutoUpdate = false;
    this.map.name = 'map-overlays';
    parent.add(this.map);
    this.groups = {};
    for (const name of ['scan', 'costmap', 'grid', 'plan']) {
      this.groups[name] = new THREE.Group();
      this.groups[name].name = name;
      this.map.add(this.groups[name]);
    }
    this.gps = new THREE.Group();    // east-north-up around the first fix, placed where the robot was then
    this.gps.name = 'gps';
    this.gps.matrixAutoUpdate = false;
    parent.add(this.gps);
    this.gpsAnchor = null;
    this.costmaps = new Map();
    this.gridVersion = null;
    on('scan3d', (d) => this.scan(d));
    on('costmap', (d) => this.costmap(d));
    on('plan', (d) => this.plan(d));
    on('live_map', (d) => this.grid(d));
    on('fix', (d) => this.track(d));
  }

  replace(group, object) {
    for (const child of [...group.children]) { group.remove(child); disposeTree(child); }
    if (object) group.add(object);
    this.requestDraw();
  }

  // The `scan3d` channel: the returns in the map frame with their heights, placed by the server through TF
  // at the scan's stamp (a tilted laser's returns slope, a laser 40 cm up draws 40 cm up).
  scan(d) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(d.points || []), 3));
    this.replace(this.groups.scan, new THREE.Points(geometry,
      new THREE.PointsMaterial({ color: 0xff3b30, size: 4, sizeAttenuation: false })));
  }

  async costmap(d) {
    for (const layer of d.costmaps || []) {
      if (!layer.data) continue;  // unchanged since the last grid with cells
      const canvas = await renderCostmap(layer);
      const texture = new THREE.CanvasTexture(canvas);
      texture.magFilter = THREE.NearestFilter;
      const plane = groundPlane(texture, layer.width * layer.resolution, layer.height * layer.resolution,
        layer.origin, 0.01);
      plane.material.opacity = 0.6;
      const old = this.costmaps.get(layer.topic);
      if (old) { this.groups.costmap.remove(old); disposeTree(old); }
      this.costmaps.set(layer.topic, plane);
      this.groups.costmap.add(plane);
    }
    this.requestDraw();
  }

  grid(d) {
    if (d.version === this.gridVersion) return;
    this.gridVersion = d.version;
    const url = at(`/api/maps/${encodeURIComponent(d.name)}/image?v=${d.version}`);
    new THREE.TextureLoader().load(url, (texture) => {
      texture.magFilter = THREE.NearestFilter;
      texture.colorSpace = THREE.SRGBColorSpace;
      this.replace(this.groups.grid, groundPlane(texture, d.width_px * d.resolution_m, d.height_px * d.resolution_m,
        d.origin, 0));
    });
  }

  plan(d) {
    const points = (d.points || []).map(([x, y]) => new THREE.Vector3(x, y, 0.05));
    this.replace(this.groups.plan, points.length < 2 ? null : new THREE.Line(
      new THREE.BufferGeometry().setFromPoints(points), new THREE.LineBasicMaterial({ color: 0x3fb950 })));
  }

  // The GPS track in metres east and north of its first point (equirectangular: a few km around it).
  track(d) {
    const track = d.track || [];
    if (!track.length) { this.replace(this.gps, null); return; }
    const [lng0, lat0] = track[0];
    const k = Math.cos(lat0 * Math.PI / 180);
    const points = track.map(([lng, lat]) => new THREE.Vector3(
      (lng - lng0) * Math.PI / 180 * EARTH_M * k, (lat - lat0) * Math.PI / 180 * EARTH_M, 0.05));
    if (points.length === 1) points.push(points[0].clone());
    this.replace(this.gps, new THREE.Line(new THREE.BufferGeometry().setFromPoints(points),
      new THREE.LineBasicMaterial({ color: 0xd29922 })));
    this.gpsFirst = this.gpsFirst || [lng0, lat0];
  }

  place(poses, robotAt) {
    const inMap = poses.inFixed(this.mapFrame || 'map');
    this.map.visible = Boolean(inMap);
    if (inMap) { this.map.matrix.copy(inMap); this.map.matrixWorldNeedsUpdate = true; }
    // ENU is anchored where the robot was at the first fix heard by this page (x east, y north: REP 103's
    // ENU, with the fixed frame's axes taken as east and north, as a map frame from a GPS-fused
    // robot_localization is).
    if (this.gpsFirst && !this.gpsAnchor) this.gpsAnchor = robotAt.clone();
    if (this.gpsAnchor) { this.gps.matrix.makeTranslation(this.gpsAnchor.x, this.gpsAnchor.y, 0); }
    this.gps.matrixWorldNeedsUpdate = true;
  }
}
