// The live map: a floorplan on an HTML5 canvas with the robot, its goal, its path and the map's
// waypoints, with no map library. This entry module owns the page's state (S) and wires the parts
// in livemap/: geometry (world <-> pixel <-> screen), view (pan and zoom), draw (the canvas),
// readout (the text and window.liveMapState), input (pointer, wheel, keys) and network (goals and
// live data). The page renders with its data in #livemap-data; the event stream keeps it current.
import { geometryOf, pixelToWorld, screenToWorld, worldToPixel, worldToScreen } from './geometry.js';
import { createViewport } from './view.js';
import { drawScene } from './draw.js';
import { publish, say } from './readout.js';
import { attachInput } from './input.js';
import { follow, mapPageUrl, sendGoal } from './network.js';
import { POSE_HINT, POSE_MODE, finishPoseGesture } from './initial_pose.js';
import { createLayers } from './layers/layers.js';
import { attachNav2 } from '../nav2/panel.js';
import { drawNav2 } from '../nav2/draw.js';
import { _ } from '../core/i18n.js';

export { worldToPixel, pixelToWorld };

const data = JSON.parse(document.getElementById('livemap-data').textContent);
const root = document.getElementById('livemap');
const stage = document.getElementById('livemap-stage');
const canvas = document.getElementById('livemap-canvas');
const ctx = canvas.getContext('2d');
const $ = (id) => document.getElementById(id);

const params = data.map_state.map_parameters;
const S = {
  map: data.map.name,
  label: data.map.label,
  source: data.map.source,
  version: data.map.version,
  geometry: geometryOf(params),
  botRadiusM: params.bot_radius / 100,
  waypoints: params.waypoints,
  keepOut: data.map.keep_out || [],
  pose: null,
  goal: null,
  plan: data.plan,
  serverState: 'connecting',
  view: { scale: 1, ox: 0, oy: 0 },
  size: { width: 0, height: 0 },  // the canvas in CSS pixels
  fitted: false,
  tracking: false,
  mode: 'pan',
  gesture: null,
  preview: null,
  cursor: null,
  imageLoaded: false,
  lastGoal: null,
  lastInitialPose: null,
  drawCount: 0,
};
const cp = params.current_pose;
if (cp && cp.x !== undefined) S.pose = { x: cp.x, y: cp.y, yaw: cp.yaw, frame_id: cp.frame_id, stale: cp.stale };
const gp = params.goal_pose;
if (gp && gp.x !== undefined) S.goal = { x: gp.x, y: gp.y, yaw: gp.yaw, frame_id: gp.frame_id };

const image = new Image();
image.decoding = 'async';
image.onload = () => { S.imageLoaded = true; root.dataset.imageLoaded = 'yes'; requestDraw(); };
image.onerror = () => say(_('Could not load the floorplan image of %(map)s.', { map: S.label }), true);
image.src = data.map.urls.image;

// --- frames: any number of changes between two animation frames cost one draw ---

const noPose = () => !S.pose || S.pose.stale || S.serverState !== 'live';

function draw() {
  const drawn = drawScene(ctx, {
    image: S.imageLoaded ? image : null, geometry: S.geometry, view: S.view, size: S.size,
    dpr: window.devicePixelRatio || 1, plan: S.plan, waypoints: S.waypoints, goal: S.goal, pose: S.pose,
    poseStale: noPose(), preview: S.preview, botRadiusM: S.botRadiusM, keepOut: S.keepOut, layers,
  });
  drawn.nav2 = drawNav2(ctx, (x, y) => worldToScreen(S.geometry, S.view, x, y), S);
  S.drawCount += 1;
  publish(root, S, drawn, noPose());
}

let drawPending = false;
function requestDraw() {
  if (drawPending) return;
  drawPending = true;
  requestAnimationFrame(() => { drawPending = false; draw(); });
}

const viewport = createViewport(S, requestDraw);
const layers = createLayers(document.getElementById('livemap-layers'), requestDraw);

function resize() {
  const rect = stage.getBoundingClientRect();
  const width = Math.max(1, Math.floor(rect.width));
  const height = Math.max(1, Math.floor(rect.height));
  const dpr = window.devicePixelRatio || 1;
  viewport.resize(width, height);
  canvas.width = Math.round(width * dpr);
  canvas.height = Math.round(height * dpr);
  canvas.style.width = `${width}px`;
  canvas.style.height = `${height}px`;
  draw();
}

// --- modes ---

function setTracking(on) {
  S.tracking = on;
  $('livemap-track').checked = on;
  if (on) viewport.centreOnRobot();
  requestDraw();
}

const stopTracking = () => { if (S.tracking) setTracking(false); };

function setMode(mode) {
  S.mode = mode;
  S.preview = null;
  $('livemap-goal-mode').setAttribute('aria-pressed', mode === 'goal' ? 'true' : 'false');
  $('livemap-pose-mode').setAttribute('aria-pressed', mode === POSE_MODE ? 'true' : 'false');
  root.dataset.mode = mode;
  canvas.style.cursor = mode === 'pan' ? 'grab' : 'crosshair';
  if (mode === 'goal') say(_('Click the goal, or press and drag towards the heading you want. Esc cancels.'));
  if (mode === POSE_MODE) say(POSE_HINT);
  requestDraw();
}

const nav2 = attachNav2(S, { redraw: requestDraw, say });
// NavigateToPose when the server says goals go there (ROVER_WEB_NAV2_GOAL_MODE), else the goal topic.
const goal = (x, y, yaw, what) => (nav2.via() === 'action'
  ? nav2.sendGoal(x, y, yaw, what) : sendGoal(S, x, y, yaw, what, requestDraw));

window.liveMap = {
  worldToScreen: (x, y) => worldToScreen(S.geometry, S.view, x, y),
  screenToWorld: (sx, sy) => screenToWorld(S.geometry, S.view, sx, sy),
  worldToPixel: (x, y) => worldToPixel(S.geometry, x, y),
};

// --- wiring ---

attachInput(canvas, S, {
  viewport, redraw: requestDraw, setMode, stopTracking, sendGoal: goal, addToRoute: nav2.addToRoute,
  livePose: () => (S.pose && !noPose() ? S.pose : null),
  setPose: (sx, sy, ex, ey) => finishPoseGesture(S, sx, sy, ex, ey, S.pose, requestDraw),
});

$('livemap-zoom-in').addEventListener('click', () => viewport.zoomCentre(1.25));
$('livemap-zoom-out').addEventListener('click', () => viewport.zoomCentre(0.8));
$('livemap-fit').addEventListener('click', () => { setTracking(false); viewport.fit(); });
$('livemap-track').addEventListener('change', (event) => setTracking(event.target.checked));
$('livemap-goal-mode').addEventListener('click', () => setMode(S.mode === 'goal' ? 'pan' : 'goal'));
$('livemap-pose-mode').addEventListener('click', () => setMode(S.mode === POSE_MODE ? 'pan' : POSE_MODE));
$('livemap-select').addEventListener('change', (event) => {
  const option = event.target.selectedOptions[0];
  if (option && option.dataset.page) window.location.assign(option.dataset.page);
});
for (const button of document.querySelectorAll('[data-route-add]')) {
  button.addEventListener('click', () => {
    const w = S.waypoints[Number(button.dataset.routeAdd)];
    if (w) nav2.addToRoute(w);
  });
}
for (const button of document.querySelectorAll('[data-waypoint]')) {
  button.addEventListener('click', () => {
    const w = S.waypoints[Number(button.dataset.waypoint)];
    if (w) goal(w.x, w.y, w.yaw, w.name);
  });
}

follow(S, {
  redraw: requestDraw,
  robotMoved: () => { if (S.tracking) viewport.centreOnRobot(); },
  // A live grid that appeared after the page was rendered joins the map list.
  mapListed: (m) => {
    const select = $('livemap-select');
    if ([...select.options].some((o) => o.value === m.name)) return;
    const option = document.createElement('option');
    option.value = m.name;
    option.textContent = m.label;
    option.dataset.page = mapPageUrl(m.name);
    select.append(option);
  },
  // Swapped in once loaded, so the old floorplan stays up meanwhile.
  newImage: (url) => {
    const next = new Image();
    next.onload = () => { image.src = next.src; };
    next.src = url;
  },
});

canvas.style.cursor = 'grab';
new ResizeObserver(resize).observe(stage);
