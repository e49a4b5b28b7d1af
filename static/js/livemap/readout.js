// What is read rather than drawn: the text beside the canvas, its scale bar, the message line, and
// window.liveMapState, which mirrors what was drawn for the browser tests and curious operators.
import { scaleBar } from './draw.js';
import { _, ngettext, formatNumber, formatUnit } from '../core/i18n.js';

const $ = (id) => document.getElementById(id);

export const fmt = (v, digits = 2) => (Number.isFinite(v) ? formatNumber(v, digits) : '—');
export const degrees = (rad) => formatUnit(Math.round((rad * 180) / Math.PI), '°');
// "x, y m" with the language's separator between the two (a comma is Spanish's decimal sign).
export const metres = (x, y, digits = 2) => _('%(x)s, %(y)s m', { x: fmt(x, digits), y: fmt(y, digits) });

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
    pill.textContent = poseState === 'live' ? _('pose live') : _('no pose');
    root.dataset.poseState = poseState;
  }
  $('livemap-robot').textContent = S.pose
    ? `${metres(S.pose.x, S.pose.y)} · ${degrees(S.pose.yaw)}${stale ? ` ${_('(stale)')}` : ''}` : '—';
  $('livemap-goal').textContent = S.goal ? `${metres(S.goal.x, S.goal.y)} · ${degrees(S.goal.yaw)}` : '—';
  $('livemap-path').textContent = S.plan && S.plan.points.length
    ? ngettext('%(num)d pose', '%(num)d poses', S.plan.length) + (S.plan.points.length < S.plan.length
      ? ` ${_('(%(drawn)d drawn)', { drawn: S.plan.points.length })}` : '') : '—';
  $('livemap-cursor').textContent = S.cursor ? metres(S.cursor[0], S.cursor[1]) : '—';
  const cmPerScreenPx = (S.geometry.res * 100) / S.view.scale;
  $('livemap-scale').textContent = _('%(cm)s cm per pixel', { cm: fmt(cmPerScreenPx, cmPerScreenPx < 1 ? 2 : 1) });
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
