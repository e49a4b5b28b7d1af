// One 3D view (the /3d page or a dashboard card): a three.js scene in the fixed frame the operator
// picks, z up as in ROS, with the robot's model, TF axes, markers and the point cloud as layers.
// It draws only while shown: a hidden tab or a card scrolled out of sight stops the drawing loop and
// the cloud's long poll (the `view3d` channel is small and shared with the page's other channels).
import * as THREE from './three.js';
import { api, at } from '../core/api.js';
import { on } from '../live/live.js';
import { onThemeChange, themeColour } from '../core/theme.js';
import { CloudLayer } from './cloud.js';
import { MarkerLayer } from './markers.js';
import { Overlays } from './overlays.js';
import { Poses } from './poses.js';
import { RobotModel } from './robot.js';
import { TfAxes } from './tf_axes.js';
import { _, ngettext, said } from '../core/i18n.js';

export function webglMissing() {
  try {
    const canvas = document.createElement('canvas');
    return !(canvas.getContext('webgl2') || canvas.getContext('webgl'));
  } catch {
    return true;
  }
}

export class Viewer {
  constructor(container, { status = null } = {}) {
    this.container = container;
    this.statusEl = status;
    this.poses = new Poses();
    this.renderer = new THREE.WebGLRenderer({ antialias: false });
    this.renderer.setPixelRatio(1);
    // The theme's ground (--scene-bg): dark, or light for daylight; again on a theme change.
    const ground = () => this.renderer.setClearColor(new THREE.Color(themeColour('--scene-bg', '#1b1f24')));
    ground();
    onThemeChange(() => { ground(); this.requestDraw(); });
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(50, 1, 0.05, 2000);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(-3, -3, 2.5);
    this.controls = new THREE.OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = false;
    this.controls.addEventListener('change', () => this.requestDraw());
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 2.0));
    const sun = new THREE.DirectionalLight(0xffffff, 1.0);
    sun.position.set(5, -3, 10);
    this.scene.add(sun);
    const grid = new THREE.GridHelper(20, 20, 0x556070, 0x2c333b);
    grid.rotation.x = Math.PI / 2;  // three's grid lies in x-z; ROS's ground is x-y
    this.scene.add(grid);
    this.layers = {
      robot: new RobotModel(this.scene),
      tf: new TfAxes(this.scene),
      markers: new MarkerLayer(this.scene, at('/api/3d/mesh')),
      cloud: new CloudLayer(this.scene),
    };
    const overlays = new Overlays(this.scene, () => this.requestDraw());
    this.overlays = overlays;
    for (const name of ['scan', 'costmap', 'grid', 'plan']) this.layers[name] = { group: overlays.groups[name] };
    this.layers.gps = { group: overlays.gps };
    this.layers.tf.group.visible = false;
    this.follow = false;
    this.frames = 0;
    this.drawn = 0;
    this.shown = true;
    this.robotSeq = 0;
    this.dirty = true;
    this.layers.cloud.onFrame = () => { this.layers.cloud.place(this.poses); this.requestDraw(); };
    on('view3d', (data) => { this.poses.update(data); this.placeAll(); });
    on('view3d_robot', (data) => { if (data.seq !== this.robotSeq) this.loadRobot(); });
    on('view3d_markers', (data) => { this.layers.markers.set(data.markers || []); this.placeAll(); });
    new ResizeObserver(() => this.resize()).observe(container);
    new IntersectionObserver((entries) => this.setShown(entries.some((e) => e.isIntersecting)))
      .observe(container);
    document.addEventListener('visibilitychange', () => this.setShown(!document.hidden));
    this.resize();
    this.loadRobot();
    this.loop();
  }

  status(text, state = '') {
    if (!this.statusEl) return;
    this.statusEl.textContent = text;
    this.statusEl.dataset.state = state;
  }

  async loadRobot() {
    let description;
    try {
      description = await api('GET', '/api/3d/robot');
    } catch (err) {
      this.status(_("the robot's description was not read: %(reason)s", { reason: err.message }), 'error');
      return;
    }
    this.robotSeq = description.seq || 0;
    this.description = description;
    this.poses.base = description.base_frame || this.poses.base;
    this.poses.aliases = { map: description.map_frame || 'map', odom: description.odom_frame || 'odom' };
    this.overlays.mapFrame = description.map_frame || 'map';
    this.updateCloud();  // the cloud needs only its topic, not a good model
    if (description.state === 'waiting') { this.status(said(description, 'message'), 'waiting'); return; }
    if (description.state === 'error') { this.status(_('URDF refused: %(reason)s', { reason: said(description.error, 'message') }), 'error'); return; }
    await this.layers.robot.build(description);
    this.container.dataset.robot = description.name;
    this.container.dataset.links = String(this.layers.robot.links.size);
    const meshErrors = this.layers.robot.meshErrors;
    this.status(meshErrors.length
      ? ngettext('%(robot)s: %(num)d mesh not drawn: %(first)s', '%(robot)s: %(num)d meshes not drawn: %(first)s', meshErrors.length,
        { robot: description.name, first: meshErrors[0] })
      : ngettext('%(robot)s: %(num)d link', '%(robot)s: %(num)d links', this.layers.robot.links.size, { robot: description.name }),
    meshErrors.length ? 'warn' : 'ok');
    this.container.dataset.meshErrors = String(meshErrors.length);
    this.placeAll();
  }

  setFixed(name) {
    this.poses.fixed = name;
    this.placeAll();
  }

  setLayer(name, visible) {
    const layer = this.layers[name];
    layer.group.visible = visible;
    if (name === 'cloud') this.updateCloud();
    this.requestDraw();
  }

  setShown(shown) {
    this.shown = shown && !document.hidden;
    this.updateCloud();
    if (this.shown) this.requestDraw();
  }

  updateCloud() {
    const cloud = this.layers.cloud;
    if (this.shown && cloud.group.visible && this.description?.cloud_topic) cloud.start();
    else cloud.stop();
  }

  placeAll() {
    const fixedKnown = Boolean(this.poses.fixedInverse());
    this.container.dataset.fixedKnown = String(fixedKnown);
    this.container.dataset.tfLinks = String(this.layers.robot.place(this.poses));
    this.layers.tf.place(this.poses);
    this.layers.markers.place(this.poses);
    this.layers.cloud.place(this.poses);
    this.overlays.place(this.poses, this.layers.robot.rootPosition());
    if (this.follow) {
      const target = this.layers.robot.rootPosition();
      this.camera.position.add(target.clone().sub(this.controls.target));
      this.controls.target.copy(target);
      this.controls.update();
    }
    this.requestDraw();
  }

  topDown() {
    const target = this.layers.robot.rootPosition();
    this.controls.target.copy(target);
    this.camera.position.set(target.x, target.y - 0.001, target.z + 8);
    this.controls.update();
    this.requestDraw();
  }

  resize() {
    const { clientWidth: w, clientHeight: h } = this.container;
    if (!w || !h) return;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestDraw();
  }

  requestDraw() { this.dirty = true; }

  // Draws when something changed (or continuously while measured: data-continuous), never while hidden.
  loop() {
    requestAnimationFrame(() => this.loop());
    if (!this.shown) return;
    if (!this.dirty && this.container.dataset.continuous !== 'yes') return;
    this.dirty = false;
    this.renderer.render(this.scene, this.camera);
    this.drawn += 1;
    this.container.dataset.drawn = String(this.drawn);
  }

  // Where a point of the fixed frame is drawn, in CSS pixels from the canvas's top left (tests use it).
  project(x, y, z) {
    const v = new THREE.Vector3(x, y, z).project(this.camera);
    const rect = this.renderer.domElement.getBoundingClientRect();
    return { x: (v.x + 1) / 2 * rect.width, y: (1 - v.y) / 2 * rect.height };
  }
}
