// Pointer, wheel and keyboard on the canvas. One pointer pans (or, in goal mode, gives a goal),
// two pinch, a click on a waypoint sends it; what the gestures change goes through `act`.
import { gestureYaw, isDrag, screenToPixel, screenToWorld, worldToScreen } from './geometry.js';
import { POSE_MODE } from './initial_pose.js';
import { _ } from '../core/i18n.js';

const WAYPOINT_HIT_PX = 12;
// Modes whose press-and-drag draws an arrow and sends it (a goal, or the initial pose) instead of panning.
const ARROW_TOOLS = new Set(['goal', POSE_MODE]);
const KEY_PAN_PX = 60;

// The waypoint nearest screen point (sx, sy), if one is within reach of a finger.
export function waypointAt(g, view, waypoints, sx, sy) {
  let best = null;
  let bestDistance = WAYPOINT_HIT_PX;
  for (const w of waypoints) {
    const [wx, wy] = worldToScreen(g, view, w.x, w.y);
    const d = Math.hypot(wx - sx, wy - sy);
    if (d <= bestDistance) { best = w; bestDistance = d; }
  }
  return best;
}

const midpoint = (a, b) => [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
const spread = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]) || 1;

// S: the page's model. act: { viewport, redraw, setMode(mode), stopTracking(), livePose() (the
// pose when it is live, else null), sendGoal(x, y, yaw, what), setPose(sx, sy, ex, ey) (screen points) }.
export function attachInput(canvas, S, act) {
  const { viewport, redraw } = act;
  const pointers = new Map();
  const local = (event) => {
    const rect = canvas.getBoundingClientRect();
    return [event.clientX - rect.left, event.clientY - rect.top];
  };
  const restCursor = () => { canvas.style.cursor = ARROW_TOOLS.has(S.mode) ? 'crosshair' : 'grab'; };

  function startPinch() {
    const [a, b] = [...pointers.values()];
    S.gesture = { kind: 'pinch', distance: spread(a, b), scale: S.view.scale, anchor: screenToPixel(S.view, ...midpoint(a, b)) };
    S.preview = null;
  }

  // Shift held: the point joins the Nav2 route being made (act.addToRoute) instead of going as a goal.
  function sendGoalFrom(sx, sy, ex, ey, toRoute) {
    const [x, y] = screenToWorld(S.geometry, S.view, sx, sy);
    const yaw = gestureYaw(S.geometry, sx, sy, ex, ey, x, y, act.livePose());
    if (toRoute && act.addToRoute) act.addToRoute({ x, y, yaw });
    else act.sendGoal(x, y, yaw, _('map point'));
  }

  canvas.addEventListener('pointerdown', (event) => {
    canvas.focus({ preventScroll: true });
    try { canvas.setPointerCapture(event.pointerId); } catch { /* a pointer already gone */ }
    pointers.set(event.pointerId, local(event));
    if (pointers.size === 2) { startPinch(); return; }
    if (pointers.size > 2) return;
    const [sx, sy] = local(event);
    S.gesture = { kind: ARROW_TOOLS.has(S.mode) ? S.mode : 'pan', sx, sy, lx: sx, ly: sy, moved: false };
    if (ARROW_TOOLS.has(S.mode)) S.preview = { sx, sy, ex: sx, ey: sy, tool: S.mode };
    else canvas.style.cursor = 'grabbing';
    redraw();
  });

  canvas.addEventListener('pointermove', (event) => {
    const [x, y] = local(event);
    S.cursor = screenToWorld(S.geometry, S.view, x, y);
    if (!pointers.has(event.pointerId)) { redraw(); return; }
    pointers.set(event.pointerId, [x, y]);
    const gesture = S.gesture;
    if (!gesture) return;
    if (gesture.kind === 'pinch' && pointers.size >= 2) {
      const [a, b] = [...pointers.values()];
      viewport.showPixelAt(gesture.scale * (spread(a, b) / gesture.distance), gesture.anchor, ...midpoint(a, b));
      act.stopTracking();
      return;
    }
    if (isDrag(gesture.sx, gesture.sy, x, y)) gesture.moved = true;
    if (gesture.kind === 'pan' && gesture.moved) {
      viewport.panBy(x - gesture.lx, y - gesture.ly);
      act.stopTracking();
    } else if (ARROW_TOOLS.has(gesture.kind)) {
      S.preview = { sx: gesture.sx, sy: gesture.sy, ex: x, ey: y, tool: gesture.kind };
      redraw();
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
    restCursor();
    const [x, y] = local(event);
    if (!cancelled && gesture.kind === 'goal') {
      sendGoalFrom(gesture.sx, gesture.sy, x, y, event.shiftKey);
      if (!event.shiftKey) act.setMode('pan');  // like RViz's goal tool: one goal, then back to moving the map
    } else if (!cancelled && gesture.kind === POSE_MODE) {
      act.setPose(gesture.sx, gesture.sy, x, y);
      act.setMode('pan');
    } else if (!cancelled && gesture.kind === 'pan' && !gesture.moved) {
      const w = waypointAt(S.geometry, S.view, S.waypoints, x, y);
      if (w) act.sendGoal(w.x, w.y, w.yaw, w.name);
    }
    redraw();
  }

  canvas.addEventListener('pointerup', (event) => endPointer(event, false));
  canvas.addEventListener('pointercancel', (event) => endPointer(event, true));
  canvas.addEventListener('pointerleave', () => { S.cursor = null; redraw(); });

  canvas.addEventListener('wheel', (event) => {
    event.preventDefault();
    const [x, y] = local(event);
    const delta = event.deltaMode === 1 ? event.deltaY * 16 : event.deltaY;  // lines to pixels
    viewport.zoomAt(Math.exp(-delta * 0.0015), x, y);
    if (S.tracking) viewport.centreOnRobot();
  }, { passive: false });

  canvas.addEventListener('keydown', (event) => {
    const keys = {
      '+': () => viewport.zoomCentre(1.25), '=': () => viewport.zoomCentre(1.25),
      '-': () => viewport.zoomCentre(0.8), '0': () => viewport.fit(),
      g: () => act.setMode(S.mode === 'goal' ? 'pan' : 'goal'), Escape: () => act.setMode('pan'),
      p: () => act.setMode(S.mode === POSE_MODE ? 'pan' : POSE_MODE),
      ArrowLeft: () => viewport.panBy(KEY_PAN_PX, 0), ArrowRight: () => viewport.panBy(-KEY_PAN_PX, 0),
      ArrowUp: () => viewport.panBy(0, KEY_PAN_PX), ArrowDown: () => viewport.panBy(0, -KEY_PAN_PX),
    };
    const action = keys[event.key];
    if (!action) return;
    event.preventDefault();
    if (event.key.startsWith('Arrow')) act.stopTracking();
    action();
  });
}
