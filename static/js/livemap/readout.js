// What is read rather than drawn: the text beside the canvas, its scale bar, the message line, and
// window.liveMapState, which mirrors what was drawn for the browser tests and curious operators.
import { scaleBar } from './draw.js';

const $ = (id) => document.getElementById(id);

export const fmt = (v, digits = 2) => (Number.isFinite(v) ? v.toFixed(digits) : '—');
export const degrees = (rad) => `${Math.round((rad * 180) / Math.PI)}°`;

export function say(text, isError = false) {
  const el = $('livemap-message');
  el.textContent = text;
  el.dataset.kind = isError ? 'error' : 'ok';
}

function showScaleBar(S) {
  const { widthPx, label } = scaleBar(S.geometry, S.view);
  const bar = $('livemap-scalebar');
  bar.querySelector('span').style.width = `${widthPx}px`;
  bar.querySelector('b').textContent = label;
}

// S: the page's model (livemap.js); drawn: what drawScene returned; stale: no live pose to trust.
export function publish(root, S, drawn, stale) {
  showScaleBar(S);
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
  $('livemap-pose-mode').setAttribute('aria-pressed', S.mode === 'pose' ? 'true' : 'false');
  root.dataset.mode = S.mode;
  window.liveMapState = {
    map: S.map, label: S.label, source: S.source, version: S.version, mode: S.mode, tracking: S.tracking,
    noPose: stale, poseState, serverState: S.serverState, imageLoaded: S.imageLoaded,
    geometry: { ...S.geometry },
    view: { scale: S.view.scale, offsetX: S.view.ox, offsetY: S.view.oy, cmPerScreenPixel: cmPerScreenPx },
    canvas: { width: S.size.width, height: S.size.height, dpr: window.devicePixelRatio || 1 },
    ...drawn, lastGoal: S.lastGoal, lastInitialPose: S.lastInitialPose, drawCount: S.drawCount,
  };
}
