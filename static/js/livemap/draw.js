// The canvas. drawScene paints one frame from a plain description of it and returns where things
// landed on screen (published for tests and the curious); it keeps no state between frames.
import { insideMap, isDrag, screenAngle, screenOfMapYaw, worldToScreen } from './geometry.js';
import { formatUnit } from '../core/i18n.js';
import { themeColour } from '../core/theme.js';

export const COLORS = { robot: '#1f6feb', robotStale: '#6e7681', heading: '#ffffff', goal: '#f0883e',
  plan: '#3fb950', preview: '#f0883e', keepOut: '#f85149', posePreview: '#56d4dd',
  // Names are text: light violet on the dark canvas, dark violet on the daylight one.
  get waypoint() { return themeColour('--plot-5', '#d2a8ff'); },
  // Around the map (and the shadow under names): the theme's, so the canvas is light in daylight.
  get background() { return themeColour('--canvas-bg', '#0b0f13'); } };
// The robot at its real size, but never smaller than a dot one can find.
const MIN_ROBOT_PX = 5;

export const robotRadiusPx = (botRadiusM, g, view) => Math.max(MIN_ROBOT_PX, (botRadiusM / g.res) * view.scale);

function arrow(ctx, x, y, angle, length, color, width = 3) {
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

function drawPlan(ctx, toScreen, plan) {
  if (!plan || plan.points.length <= 1) return;
  ctx.strokeStyle = COLORS.plan;
  ctx.lineWidth = 2.5;
  ctx.lineJoin = 'round';
  ctx.beginPath();
  plan.points.forEach(([x, y], i) => {
    const [sx, sy] = toScreen(x, y);
    if (i === 0) ctx.moveTo(sx, sy); else ctx.lineTo(sx, sy);
  });
  ctx.stroke();
}

// The name goes right of the marker, or left of it when it would run off the canvas (a phone's
// narrow map cut the names near its right edge), and is kept inside top and bottom. Returns the
// label's box in screen pixels.
function drawWaypoint(ctx, w, sx, sy, size) {
  ctx.fillStyle = COLORS.waypoint;
  ctx.beginPath();
  ctx.moveTo(sx, sy - 6); ctx.lineTo(sx + 6, sy); ctx.lineTo(sx, sy + 6); ctx.lineTo(sx - 6, sy);
  ctx.closePath();
  ctx.fill();
  const width = ctx.measureText(w.name).width;
  const half = 8;
  let left = sx + 8;
  if (left + width + 1 > size.width) left = sx - 8 - width;
  left = Math.max(0, Math.min(left, size.width - width - 1));
  const y = Math.max(half, Math.min(sy, size.height - half - 1));
  ctx.fillStyle = COLORS.background;  // a shadow, so the name reads on any floor colour
  ctx.fillText(w.name, left + 1, y + 1);
  ctx.fillStyle = COLORS.waypoint;
  ctx.fillText(w.name, left, y);
  return { left, right: left + width + 1, top: y - half, bottom: y + half + 1 };
}

function drawRobot(ctx, sx, sy, angle, radius, stale) {
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
}

// Keep-out areas (map metres, from all_maps.json): goals inside them are refused by the server.
function drawKeepOut(ctx, toScreen, areas) {
  ctx.strokeStyle = COLORS.keepOut;
  ctx.fillStyle = `${COLORS.keepOut}55`;
  ctx.lineWidth = 2;
  for (const area of areas) {
    ctx.beginPath();
    area.polygon.forEach(([x, y], i) => {
      const [sx, sy] = toScreen(x, y);
      if (i === 0) ctx.moveTo(sx, sy); else ctx.lineTo(sx, sy);
    });
    ctx.closePath();
    ctx.fill();
    ctx.stroke();
  }
}

function ring(ctx, sx, sy, radius, color) {
  ctx.strokeStyle = color;
  ctx.lineWidth = 2;
  ctx.beginPath();
  ctx.arc(sx, sy, radius, 0, 2 * Math.PI);
  ctx.stroke();
}

// scene: { image (null until loaded), geometry, view, size, dpr, plan, waypoints, goal, pose,
// poseStale, preview, botRadiusM, keepOut, layers (optional) }.
export function drawScene(ctx, scene) {
  const { geometry: g, view, size } = scene;
  const toScreen = (x, y) => worldToScreen(g, view, x, y);
  ctx.setTransform(scene.dpr, 0, 0, scene.dpr, 0, 0);
  ctx.fillStyle = COLORS.background;
  ctx.fillRect(0, 0, size.width, size.height);
  if (scene.image) {
    ctx.imageSmoothingEnabled = view.scale < 1.5;  // crisp cells when zoomed in
    ctx.drawImage(scene.image, view.ox, view.oy, g.w * view.scale, g.h * view.scale);
  }
  const { layers } = scene;  // what the robot senses (layers/layers.js): costmaps here, the rest over the plan
  if (layers) layers.drawUnder(ctx, { g, view, dpr: scene.dpr });
  const { plan } = scene;
  const drawn = { waypoints: [], pose: null, goal: null, plan: null, keep_out: (scene.keepOut || []).length };
  drawKeepOut(ctx, toScreen, scene.keepOut || []);

  drawPlan(ctx, toScreen, plan);
  if (layers) layers.drawOver(ctx, { toScreen, g, view });
  drawn.layers = layers ? layers.state() : null;
  drawn.plan = plan ? { points: plan.points.length, length: plan.length, frame_id: plan.frame_id } : null;

  ctx.font = '12px system-ui, sans-serif';
  ctx.textBaseline = 'middle';
  for (const w of scene.waypoints) {
    const [sx, sy] = toScreen(w.x, w.y);
    const label = drawWaypoint(ctx, w, sx, sy, size);
    drawn.waypoints.push({ name: w.name, screen: { x: sx, y: sy }, label });
  }

  const radius = robotRadiusPx(scene.botRadiusM, g, view);
  const { goal, pose, preview } = scene;
  if (goal) {
    const [sx, sy] = toScreen(goal.x, goal.y);
    ring(ctx, sx, sy, radius, COLORS.goal);
    arrow(ctx, sx, sy, screenOfMapYaw(g, goal.yaw), Math.max(radius * 1.8, 22), COLORS.goal);
    drawn.goal = { ...goal, screen: { x: sx, y: sy }, inside: insideMap(g, goal.x, goal.y) };
  }

  if (pose) {
    const [sx, sy] = toScreen(pose.x, pose.y);
    drawRobot(ctx, sx, sy, screenOfMapYaw(g, pose.yaw), radius, scene.poseStale);
    drawn.pose = { ...pose, screen: { x: sx, y: sy }, radius_px: radius, inside: insideMap(g, pose.x, pose.y) };
  }

  if (preview) {
    const { sx, sy, ex, ey } = preview;
    const color = preview.tool === 'pose' ? COLORS.posePreview : COLORS.preview;
    if (isDrag(sx, sy, ex, ey)) {
      arrow(ctx, sx, sy, screenAngle(sx, sy, ex, ey), Math.hypot(ex - sx, ey - sy), color, 2);
    }
    ring(ctx, sx, sy, radius, color);
  }
  return drawn;
}

function niceLength(metres) {
  const power = 10 ** Math.floor(Math.log10(metres));
  for (const step of [1, 2, 5, 10]) if (step * power >= metres) return step * power;
  return 10 * power;
}

// A round length near 100 screen pixels: its width on screen and its label.
export function scaleBar(g, view) {
  const metresPerScreenPx = g.res / view.scale;
  const metres = niceLength(100 * metresPerScreenPx);
  return { widthPx: metres / metresPerScreenPx, label: metres >= 1 ? formatUnit(metres, 'm') : formatUnit(Math.round(metres * 100), 'cm') };
}
