// The live map: a floorplan on an HTML5 canvas with the robot, its goal, its path and the map's
// waypoints. No map library: the view is one scale and one offset (screen = offset + pixel * scale),
// and world <-> image pixels follows rover_web/map_geometry.py (map_server's conventions).
// The page renders with its data in #livemap-data; the pose, goal, plan and live_map channels
// keep it current. window.liveMapState mirrors what is drawn, for tests and for curious operators.

import { api, ApiError } from './api.js';
import { on, onServerState } from './live.js';

const data = JSON.parse(document.getElementById('livemap-data').textContent);
const root = document.getElementById('livemap');
const stage = document.getElementById('livemap-stage');
const canvas = document.getElementById('livemap-canvas');
const ctx = canvas.getContext('2d');
const $ = (id) => document.getElementById(id);

const COLORS = { robot: '#1f6feb', robotStale: '#6e7681', heading: '#ffffff', goal: '#f0883e',
  plan: '#3fb950', waypoint: '#d2a8ff', preview: '#f0883e', background: '#0b0f13' };
const MIN_ROBOT_PX = 5;
const CLICK_SLOP_PX = 5;
const WAYPOINT_HIT_PX = 12;

// --- geometry (the same formulas as rover_web/map_geometry.py) ---

function geometryOf(params) {
  const { png, yaml } = params.files;
  const [ox, oy, oyaw = 0] = yaml.origin;
  return { w: png.pixel_width, h: png.pixel_height, res: yaml.resolution, ox, oy, oyaw };
}

export function worldToPixel(g, x, y) {
  let dx = x - g.ox;
  let dy = y - g.oy;
  if (g.oyaw) {
    const c = Math.cos(g.oyaw), s = Math.sin(g.oyaw);
    [dx, dy] = [c * dx + s * dy, -s * dx + c * dy];
  }
  return [dx / g.res, g.h - dy / g.res];
}

export function pixelToWorld(g, px, py) {
  let u = px * g.res;
  let v = (g.h - py) * g.res;
  if (g.oyaw) {
    const c = Math.cos(g.oyaw), s = Math.sin(g.oyaw);
    [u, v] = [c * u - s * v, s * u + c * v];
  }
  return [g.ox + u, g.oy + v];
}

const insideMap = (g, x, y) => {
  const [px, py] = worldToPixel(g, x, y);
  return px >= 0 && px <= g.w && py >= 0 && py <= g.h;
};

// --- state ---

const params = data.map_state.map_parameters;
const S = {
  map: data.map.name,
  label: data.map.label,
  source: data.map.source,
  version: data.map.version,
  geometry: geometryOf(params),
  botRadiusM: params.bot_radius / 100,
  waypoints: params.waypoints,
  pose: null,
  goal: null,
  plan: data.plan,
  serverState: 'connecting',
  view: { scale: 1, ox: 0, oy: 0 },
  fitted: false,
  tracking: false,
  mode: 'pan',
  gesture: null,
  preview: null,
  cursor: null,
  imageLoaded: false,
  lastGoal: null,
  drawCount: 0,
};
const cp = params.current_pose;
if (cp && cp.x !== undefined) S.pose = { x: cp.x, y: cp.y, yaw: cp.yaw, frame_id: cp.frame_id, stale: cp.stale };
const gp = params.goal_pose;
if (gp && gp.x !== undefined) S.goal = { x: gp.x, y: gp.y, yaw: gp.yaw, frame_id: gp.frame_id };

const image = new Image();
image.decoding = 'async';
image.onload = () => { S.imageLoaded = true; root.dataset.imageLoaded = 'yes'; requestDraw(); };
image.onerror = () => message(`Could not load the floorplan image of ${S.label}.`, true);
image.src = data.map.urls.image;

// --- view ---

let cssWidth = 0;
let cssHeight = 0;

const toScreen = (px, py) => [S.view.ox + px * S.view.scale, S.view.oy + py * S.view.scale];
const fromScreen = (sx, sy) => [(sx - S.view.ox) / S.view.scale, (sy - S.view.oy) / S.view.scale];
const worldToScreen = (x, y) => toScreen(...worldToPixel(S.geometry, x, y));
const screenToWorld = (sx, sy) => pixelToWorld(S.geometry, ...fromScreen(sx, sy));

function fitScale() {
  const g = S.geometry;
  return Math.max(1e-3, 0.96 * Math.min(cssWidth / g.w, cssHeight / g.h));
}

function clampScale(scale) {
  const fit = fitScale();
  return Math.min(Math.max(scale, fit / 8), Math.max(fit * 64, 40));
}

function fit() {
  const g = S.geometry;
  S.view.scale = fitScale();
  S.view.ox = (cssWidth - g.w * S.view.scale) / 2;
  S.view.oy = (cssHeight - g.h * S.view.scale) / 2;
  S.fitted = true;
  requestDraw();
}

function zoomAt(factor, sx, sy) {
  const scale = clampScale(S.view.scale * factor);
  const [px, py] = fromScreen(sx, sy);
  S.view.scale = scale;
  S.view.ox = sx - px * scale;
  S.view.oy = sy - py * scale;
  requestDraw();
}

function zoomCentre(factor) {
  if (S.tracking && S.pose) {
    zoomAt(factor, ...worldToScreen(S.pose.x, S.pose.y));
    centreOnRobot();
  } else {
    zoomAt(factor, cssWidth / 2, cssHeight / 2);
  }
}

function panBy(dx, dy) {
  S.view.ox += dx;
  S.view.oy += dy;
  requestDraw();
}

function centreOnRobot() {
  if (!S.pose) return;
  const [sx, sy] = worldToScreen(S.pose.x, S.pose.y);
  panBy(cssWidth / 2 - sx, cssHeight / 2 - sy);
}

function setTracking(on) {
  S.tracking = on;
  $('livemap-track').checked = on;
  if (on) centreOnRobot();
  requestDraw();
}

function resize() {
  const rect = stage.getBoundingClientRect();
  const width = Math.max(1, Math.floor(rect.width));
  const height = Math.max(1, Math.floor(rect.height));
  const dpr = window.devicePixelRatio || 1;
  if (S.fitted) {  // keep what was in the middle in the middle
    S.view.ox += (width - cssWidth) / 2;
    S.view.oy += (height - cssHeight) / 2;
  }
  cssWidth = width;
  cssHeight = height;
  canvas.width = Math.round(width * dpr);
  canvas.height = Math.round(height * dpr);
  canvas.style.width = `${width}px`;
  canvas.style.height = `${height}px`;
  if (!S.fitted) fit();
  if (S.tracking) centreOnRobot();
  draw();
}

// --- drawing ---

let drawPending = false;
function requestDraw() {
  if (drawPending) return;
  drawPending = true;
  requestAnimationFrame(() => { drawPending = false; draw(); });
}

function noPose() {
  return !S.pose || S.pose.stale || S.serverState !== 'live';
}

function robotRadiusPx() {
  return Math.max(MIN_ROBOT_PX, (S.botRadiusM / S.geometry.res) * S.view.scale);
}

function arrow(x, y, angle, length, color, width = 3) {
  const ex = x + Math.cos(angle) * length;
  const ey = y - Math.sin(angle) * length;  // image y points down, map angles count up
  ctx.strokeStyle = color;
  ctx.fillStyle = color;
  ctx.lineWidth = width;
  ctx.beginPath();
  ctx.moveTo(x, y);
  ctx.lineTo(ex, ey);
  ctx.stroke();
  const head = Math.min(12, length / 2);
  ctx.beginPath();
  ctx.moveTo(ex, ey);
  ctx.lineTo(ex - head * Math.cos(angle - 0.45), ey + head * Math.sin(angle - 0.45));
  ctx.lineTo(ex - head * Math.cos(angle + 0.45), ey + head * Math.sin(angle + 0.45));
  ctx.closePath();
  ctx.fill();
}

function draw() {
  const dpr = window.devicePixelRatio || 1;
  const g = S.geometry;
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.fillStyle = COLORS.background;
  ctx.fillRect(0, 0, cssWidth, cssHeight);
  if (S.imageLoaded) {
    ctx.imageSmoothingEnabled = S.view.scale < 1.5;  // crisp cells when zoomed in
    ctx.drawImage(image, S.view.ox, S.view.oy, g.w * S.view.scale, g.h * S.view.scale);
  }
  const state = { waypoints: [], pose: null, goal: null, plan: null };

  if (S.plan && S.plan.points.length > 1) {
    ctx.strokeStyle = COLORS.plan;
    ctx.lineWidth = 2.5;
    ctx.lineJoin = 'round';
    ctx.beginPath();
    S.plan.points.forEach(([x, y], i) => {
      const [sx, sy] = worldToScreen(x, y);
      if (i === 0) ctx.moveTo(sx, sy); else ctx.lineTo(sx, sy);
    });
    ctx.stroke();
  }
  state.plan = S.plan ? { points: S.plan.points.length, length: S.plan.length, frame_id: S.plan.frame_id } : null;

  ctx.font = '12px system-ui, sans-serif';
  ctx.textBaseline = 'middle';
  for (const w of S.waypoints) {
    const [sx, sy] = worldToScreen(w.x, w.y);
    ctx.fillStyle = COLORS.waypoint;
    ctx.beginPath();
    ctx.moveTo(sx, sy - 6); ctx.lineTo(sx + 6, sy); ctx.lineTo(sx, sy + 6); ctx.lineTo(sx - 6, sy);
    ctx.closePath();
    ctx.fill();
    ctx.fillStyle = '#0b0f13';
    ctx.fillText(w.name, sx + 9, sy + 1);
    ctx.fillStyle = COLORS.waypoint;
    ctx.fillText(w.name, sx + 8, sy);
    state.waypoints.push({ name: w.name, screen: { x: sx, y: sy } });
  }

  const radius = robotRadiusPx();
  if (S.goal) {
    const [sx, sy] = worldToScreen(S.goal.x, S.goal.y);
    const angle = S.goal.yaw - g.oyaw;
    ctx.strokeStyle = COLORS.goal;
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.arc(sx, sy, radius, 0, 2 * Math.PI);
    ctx.stroke();
    arrow(sx, sy, angle, Math.max(radius * 1.8, 22), COLORS.goal);
    state.goal = { ...S.goal, screen: { x: sx, y: sy }, inside: insideMap(g, S.goal.x, S.goal.y) };
  }

  if (S.pose) {
    const [sx, sy] = worldToScreen(S.pose.x, S.pose.y);
    const angle = S.pose.yaw - g.oyaw;
    const stale = noPose();
    ctx.globalAlpha = stale ? 0.5 : 1;
    ctx.fillStyle = stale ? COLORS.robotStale : COLORS.robot;
    ctx.beginPath();
    ctx.arc(sx, sy, radius, 0, 2 * Math.PI);
    ctx.fill();
    ctx.strokeStyle = COLORS.heading;
    ctx.lineWidth = Math.max(1.5, radius / 6);
    ctx.beginPath();
    ctx.moveTo(sx, sy);
    ctx.lineTo(sx + Math.cos(angle) * radius, sy - Math.sin(angle) * radius);
    ctx.stroke();
    ctx.globalAlpha = 1;
    state.pose = { ...S.pose, screen: { x: sx, y: sy }, radius_px: radius, inside: insideMap(g, S.pose.x, S.pose.y) };
  }

  if (S.preview) {
    const { sx, sy, ex, ey } = S.preview;
    const length = Math.hypot(ex - sx, ey - sy);
    if (length >= CLICK_SLOP_PX) arrow(sx, sy, Math.atan2(sy - ey, ex - sx), length, COLORS.preview, 2);
    ctx.strokeStyle = COLORS.preview;
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.arc(sx, sy, radius, 0, 2 * Math.PI);
    ctx.stroke();
  }

  drawScaleBar();
  S.drawCount += 1;
  publishState(state);
}

function niceLength(metres) {
  const power = 10 ** Math.floor(Math.log10(metres));
  for (const step of [1, 2, 5, 10]) if (step * power >= metres) return step * power;
  return 10 * power;
}

function drawScaleBar() {
  const metresPerScreenPx = S.geometry.res / S.view.scale;
  const metres = niceLength(100 * metresPerScreenPx);
  const bar = $('livemap-scalebar');
  bar.querySelector('span').style.width = `${metres / metresPerScreenPx}px`;
  bar.querySelector('b').textContent = metres >= 1 ? `${metres} m` : `${Math.round(metres * 100)} cm`;
}

// --- page text and exposed state ---

const fmt = (v, digits = 2) => (Number.isFinite(v) ? v.toFixed(digits) : '—');
const degrees = (rad) => `${Math.round((rad * 180) / Math.PI)}°`;

function publishState(drawn) {
  const stale = noPose();
  const pill = $('livemap-pose-state');
  const poseState = !S.pose ? 'none' : stale ? 'stale' : 'live';
  if (pill.dataset.state !== poseState) {
    pill.dataset.state = poseState;
    pill.textContent = poseState === 'live' ? 'pose live' : 'no pose';
    root.dataset.poseState = poseState;
  }
  $('livemap-robot').textContent = S.pose
    ? `${fmt(S.pose.x)}, ${fmt(S.pose.y)} m · ${degrees(S.pose.yaw)}${stale ? ' (stale)' : ''}` : '—';
  $('livemap-goal').textContent = S.goal ? `${fmt(S.goal.x)}, ${fmt(S.goal.y)} m · ${degrees(S.goal.yaw)}` : '—';
  $('livemap-path').textContent = S.plan && S.plan.points.length
    ? `${S.plan.length} poses${S.plan.points.length < S.plan.length ? ` (${S.plan.points.length} drawn)` : ''}` : '—';
  $('livemap-cursor').textContent = S.cursor ? `${fmt(S.cursor[0])}, ${fmt(S.cursor[1])} m` : '—';
  const cmPerScreenPx = (S.geometry.res * 100) / S.view.scale;
  $('livemap-scale').textContent = `${fmt(cmPerScreenPx, cmPerScreenPx < 1 ? 2 : 1)} cm per pixel`;
  $('livemap-goal-mode').setAttribute('aria-pressed', S.mode === 'goal' ? 'true' : 'false');
  root.dataset.mode = S.mode;
  window.liveMapState = {
    map: S.map, label: S.label, source: S.source, version: S.version, mode: S.mode, tracking: S.tracking,
    noPose: stale, poseState, serverState: S.serverState, imageLoaded: S.imageLoaded,
    geometry: { ...S.geometry },
    view: { scale: S.view.scale, offsetX: S.view.ox, offsetY: S.view.oy, cmPerScreenPixel: cmPerScreenPx },
    canvas: { width: cssWidth, height: cssHeight, dpr: window.devicePixelRatio || 1 },
    ...drawn, lastGoal: S.lastGoal, drawCount: S.drawCount,
  };
}

window.liveMap = {
  worldToScreen: (x, y) => worldToScreen(x, y),
  screenToWorld: (sx, sy) => screenToWorld(sx, sy),
  worldToPixel: (x, y) => worldToPixel(S.geometry, x, y),
};

function message(text, isError = false) {
  const el = $('livemap-message');
  el.textContent = text;
  el.dataset.kind = isError ? 'error' : 'ok';
}

// --- goals ---

async function sendGoal(x, y, yaw, what) {
  const body = { x, y, yaw };
  S.lastGoal = { request: body, status: 'sending' };
  message(`Sending ${what}…`);
  try {
    const reply = await api('POST', `/api/maps/${encodeURIComponent(S.map)}/goal`, body);
    S.lastGoal = { request: body, status: 200, reply };  // api() resolves only on 2xx; this route answers 200
    S.goal = { x: reply.goal.x, y: reply.goal.y, yaw: reply.goal.yaw, frame_id: reply.goal.frame_id };
    message(`Goal sent: ${what} (${fmt(x)}, ${fmt(y)} m, ${degrees(yaw)}).`);
  } catch (err) {
    if (err instanceof ApiError) {
      S.lastGoal = { request: body, status: err.status, reply: err.reply || {} };
      message(`Goal refused: ${err.message}`, true);
    } else {
      S.lastGoal = { request: body, status: 'failed' };
      message('Goal not sent: the server did not answer.', true);
    }
  }
  requestDraw();
}

function setMode(mode) {
  S.mode = mode;
  S.preview = null;
  $('livemap-goal-mode').setAttribute('aria-pressed', mode === 'goal' ? 'true' : 'false');
  root.dataset.mode = mode;
  canvas.style.cursor = mode === 'goal' ? 'crosshair' : 'grab';
  if (mode === 'goal') message('Click the goal, or press and drag towards the heading you want. Esc cancels.');
  requestDraw();
}

function waypointAt(sx, sy) {
  let best = null;
  let bestDistance = WAYPOINT_HIT_PX;
  for (const w of S.waypoints) {
    const [wx, wy] = worldToScreen(w.x, w.y);
    const d = Math.hypot(wx - sx, wy - sy);
    if (d <= bestDistance) { best = w; bestDistance = d; }
  }
  return best;
}

function goalFromGesture(sx, sy, ex, ey) {
  const [x, y] = screenToWorld(sx, sy);
  let yaw;
  if (Math.hypot(ex - sx, ey - sy) >= CLICK_SLOP_PX) {
    yaw = Math.atan2(sy - ey, ex - sx) + S.geometry.oyaw;  // screen angle back to the map frame
  } else if (S.pose && !noPose()) {
    yaw = Math.atan2(y - S.pose.y, x - S.pose.x);  // a plain click: face the way there
  } else {
    yaw = 0;
  }
  yaw = Math.atan2(Math.sin(yaw), Math.cos(yaw));
  sendGoal(x, y, yaw, 'map point');
}

// --- pointer, wheel and keyboard ---

const pointers = new Map();
const local = (event) => {
  const rect = canvas.getBoundingClientRect();
  return [event.clientX - rect.left, event.clientY - rect.top];
};

function startPinch() {
  const [a, b] = [...pointers.values()];
  S.gesture = {
    kind: 'pinch', distance: Math.hypot(a[0] - b[0], a[1] - b[1]) || 1, scale: S.view.scale,
    anchor: fromScreen((a[0] + b[0]) / 2, (a[1] + b[1]) / 2),
  };
  S.preview = null;
}

canvas.addEventListener('pointerdown', (event) => {
  canvas.focus({ preventScroll: true });
  try { canvas.setPointerCapture(event.pointerId); } catch { /* a pointer already gone */ }
  pointers.set(event.pointerId, local(event));
  if (pointers.size === 2) { startPinch(); return; }
  if (pointers.size > 2) return;
  const [sx, sy] = local(event);
  S.gesture = { kind: S.mode === 'goal' ? 'goal' : 'pan', sx, sy, lx: sx, ly: sy, moved: false };
  if (S.mode === 'goal') S.preview = { sx, sy, ex: sx, ey: sy };
  else canvas.style.cursor = 'grabbing';
  requestDraw();
});

canvas.addEventListener('pointermove', (event) => {
  const [x, y] = local(event);
  S.cursor = screenToWorld(x, y);
  if (!pointers.has(event.pointerId)) { requestDraw(); return; }
  pointers.set(event.pointerId, [x, y]);
  const gesture = S.gesture;
  if (!gesture) return;
  if (gesture.kind === 'pinch' && pointers.size >= 2) {
    const [a, b] = [...pointers.values()];
    const distance = Math.hypot(a[0] - b[0], a[1] - b[1]) || 1;
    const [mx, my] = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
    S.view.scale = clampScale(gesture.scale * (distance / gesture.distance));
    S.view.ox = mx - gesture.anchor[0] * S.view.scale;
    S.view.oy = my - gesture.anchor[1] * S.view.scale;
    if (S.tracking) setTracking(false);
    requestDraw();
    return;
  }
  if (Math.hypot(x - gesture.sx, y - gesture.sy) >= CLICK_SLOP_PX) gesture.moved = true;
  if (gesture.kind === 'pan' && gesture.moved) {
    panBy(x - gesture.lx, y - gesture.ly);
    if (S.tracking) setTracking(false);
  } else if (gesture.kind === 'goal') {
    S.preview = { sx: gesture.sx, sy: gesture.sy, ex: x, ey: y };
    requestDraw();
  }
  gesture.lx = x;
  gesture.ly = y;
});

function endPointer(event, cancelled) {
  if (!pointers.has(event.pointerId)) return;
  pointers.delete(event.pointerId);
  const gesture = S.gesture;
  if (!gesture) return;
  if (gesture.kind === 'pinch') {
    if (pointers.size < 2) S.gesture = null;  // the finger left on the map does nothing more
    return;
  }
  S.gesture = null;
  S.preview = null;
  canvas.style.cursor = S.mode === 'goal' ? 'crosshair' : 'grab';
  const [x, y] = local(event);
  if (!cancelled && gesture.kind === 'goal') {
    goalFromGesture(gesture.sx, gesture.sy, x, y);
    setMode('pan');  // like RViz's goal tool: one goal, then back to moving the map
  } else if (!cancelled && gesture.kind === 'pan' && !gesture.moved) {
    const w = waypointAt(x, y);
    if (w) sendGoal(w.x, w.y, w.yaw, w.name);
  }
  requestDraw();
}

canvas.addEventListener('pointerup', (event) => endPointer(event, false));
canvas.addEventListener('pointercancel', (event) => endPointer(event, true));
canvas.addEventListener('pointerleave', () => { S.cursor = null; requestDraw(); });

canvas.addEventListener('wheel', (event) => {
  event.preventDefault();
  const [x, y] = local(event);
  const delta = event.deltaMode === 1 ? event.deltaY * 16 : event.deltaY;
  zoomAt(Math.exp(-delta * 0.0015), x, y);
  if (S.tracking) centreOnRobot();
}, { passive: false });

canvas.addEventListener('keydown', (event) => {
  const step = 60;
  const keys = {
    '+': () => zoomCentre(1.25), '=': () => zoomCentre(1.25), '-': () => zoomCentre(0.8), '0': fit,
    g: () => setMode(S.mode === 'goal' ? 'pan' : 'goal'), Escape: () => setMode('pan'),
    ArrowLeft: () => panBy(step, 0), ArrowRight: () => panBy(-step, 0),
    ArrowUp: () => panBy(0, step), ArrowDown: () => panBy(0, -step),
  };
  const action = keys[event.key];
  if (!action) return;
  event.preventDefault();
  if (event.key.startsWith('Arrow') && S.tracking) setTracking(false);
  action();
});

// --- toolbar ---

$('livemap-zoom-in').addEventListener('click', () => zoomCentre(1.25));
$('livemap-zoom-out').addEventListener('click', () => zoomCentre(0.8));
$('livemap-fit').addEventListener('click', () => { setTracking(false); fit(); });
$('livemap-track').addEventListener('change', (event) => setTracking(event.target.checked));
$('livemap-goal-mode').addEventListener('click', () => setMode(S.mode === 'goal' ? 'pan' : 'goal'));
$('livemap-select').addEventListener('change', (event) => {
  const option = event.target.selectedOptions[0];
  if (option && option.dataset.page) window.location.assign(option.dataset.page);
});
for (const button of document.querySelectorAll('[data-waypoint]')) {
  button.addEventListener('click', () => {
    const w = S.waypoints[Number(button.dataset.waypoint)];
    if (w) sendGoal(w.x, w.y, w.yaw, w.name);
  });
}

// --- live data ---

on('pose', (p) => {
  S.pose = { x: p.x, y: p.y, yaw: p.yaw, frame_id: p.frame_id, stale: p.stale, pixels: p.pixels[S.map] || null };
  if (S.tracking && !p.stale) centreOnRobot();
  requestDraw();
});

on('goal', (g) => {
  S.goal = { x: g.x, y: g.y, yaw: g.yaw, frame_id: g.frame_id };
  requestDraw();
});

on('plan', (plan) => {
  S.plan = plan;
  requestDraw();
});

on('live_map', (m) => {
  const select = $('livemap-select');
  if (![...select.options].some((o) => o.value === m.name)) {
    const option = document.createElement('option');
    option.value = m.name;
    option.textContent = m.label;
    option.dataset.page = `/livemap/${encodeURIComponent(m.name)}`;
    select.append(option);
  }
  if (m.name !== S.map || m.version === S.version) return;
  S.version = m.version;
  const [ox, oy, oyaw = 0] = m.origin;
  S.geometry = { w: m.width_px, h: m.height_px, res: m.resolution_m, ox, oy, oyaw };
  const next = new Image();
  next.onload = () => { image.src = next.src; };
  next.src = `/api/maps/${encodeURIComponent(m.name)}/image?v=${m.version}`;
  requestDraw();
});

onServerState((state) => {
  S.serverState = state;
  requestDraw();
});

canvas.style.cursor = 'grab';
new ResizeObserver(resize).observe(stage);
