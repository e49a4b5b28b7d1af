// The point cloud layer: the newest thinned cloud from GET /api/3d/cloud (binary: rover_web/view3d/cloud.py),
// asked for again as soon as one arrives (a long poll keyed by sequence, so a viewer never gets the same
// cloud twice and a slow one skips to the newest). Only while the view is shown: stop() ends the loop.
import * as THREE from './three.js';
import { at } from '../api.js';
import { matrixOf } from './poses.js';

export function decodeCloud(buffer) {
  const view = new DataView(buffer);
  const length = view.getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, length)));
  const start = 4 + length;
  const xyz = new Float32Array(buffer, start, header.count * 3);
  const intensity = header.intensity ? new Float32Array(buffer, start + header.count * 12, header.count) : null;
  return { header, xyz, intensity };
}

// A colour ramp from blue (low) through green to red (high).
function ramp(t, out, i) {
  const v = Math.min(1, Math.max(0, t));
  out[i] = Math.min(1, Math.max(0, 2 * v - 0.5));
  out[i + 1] = 1 - Math.abs(2 * v - 1);
  out[i + 2] = Math.min(1, Math.max(0, 1.5 - 2 * v));
}

export class CloudLayer {
  constructor(parent) {
    this.group = new THREE.Group();
    this.group.name = 'cloud';
    this.group.matrixAutoUpdate = false;
    parent.add(this.group);
    this.geometry = new THREE.BufferGeometry();
    this.points = new THREE.Points(this.geometry, new THREE.PointsMaterial({ size: 3, sizeAttenuation: false,
      vertexColors: true }));
    this.group.add(this.points);
    this.colorBy = 'height';
    this.seq = 0;
    this.frame = null;
    this.running = false;
    this.received = 0;
    this.last = null;
    this.onFrame = null;
  }

  show(cloud) {
    const { header, xyz, intensity } = cloud;
    const colors = new Float32Array(header.count * 3);
    if (this.colorBy === 'intensity' && intensity) {
      const [low, high] = header.intensity_range || [0, 1];
      for (let i = 0; i < header.count; i++) ramp((intensity[i] - low) / ((high - low) || 1), colors, i * 3);
    } else {
      const [low, high] = header.extent ? [header.extent[0][2], header.extent[1][2]] : [0, 1];
      for (let i = 0; i < header.count; i++) ramp((xyz[i * 3 + 2] - low) / ((high - low) || 1), colors, i * 3);
    }
    this.geometry.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
    this.geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3));
    this.geometry.computeBoundingSphere();
    this.frame = header.frame_id;
    this.last = cloud;
  }

  // Where the cloud was taken: its frame in the fixed frame at its stamp when the server could say
  // (header.at_stamp), else the frame's latest pose.
  place(poses) {
    const atStamp = this.last?.header.at_stamp?.[poses.fixedName()];
    const m = atStamp ? matrixOf(atStamp) : (this.frame ? poses.inFixed(this.frame) : null);
    this.points.visible = Boolean(m);
    if (m) { this.group.matrix.copy(m); this.group.matrixWorldNeedsUpdate = true; }
  }

  async start() {
    if (this.running) return;
    this.running = true;
    this.controller = new AbortController();
    while (this.running) {
      try {
        const response = await fetch(at(`/api/3d/cloud?after=${this.seq}&wait=2`), { signal: this.controller.signal });
        if (response.status === 404) { this.running = false; break; }  // no cloud topic set
        const seq = Number(response.headers.get('X-Cloud-Seq') || this.seq);
        if (response.status === 200) {
          const cloud = decodeCloud(await response.arrayBuffer());
          this.received += 1;
          this.show(cloud);
          this.onFrame?.(cloud);
          this.seq = seq;
        } else if (!response.ok) {
          await new Promise((r) => setTimeout(r, 2000));  // refused (503, 403): ask again later
        } else {
          this.seq = seq;
        }
      } catch (err) {
        if (!this.running) break;
        await new Promise((r) => setTimeout(r, 1000));  // the server not reached: try again
      }
    }
  }

  stop() {
    this.running = false;
    this.controller?.abort();
  }
}
