// The replay's LiveMap: the robot's recorded pose (and its recorded goal and path) on a floorplan,
// drawn by the LiveMap page's own modules (livemap/geometry.js, view.js, draw.js, and input.js for
// pan and zoom), so a replayed pose lands on the same pixel a live one did. Nothing here sends a
// goal: the input's goal callbacks are given nothing to do, and livemap/network.js is not imported.
import { api } from '../../core/api.js';
import { geometryOf } from '../../livemap/geometry.js';
import { createViewport } from '../../livemap/view.js';
import { drawScene, scaleBar } from '../../livemap/draw.js';
import { attachInput } from '../../livemap/input.js';
import { degrees, metres } from '../../livemap/readout.js';
import { lastAtOrBefore } from './at.js';
import { _ } from '../../core/i18n.js';

const POSE_KINDS = ['pose', 'odom'];

// The pose sources a recording offers: every pose and odometry track, the robot's pose topic first.
function poseSources(data, settings) {
  const sources = [];
  for (const kind of POSE_KINDS) {
    for (const [topic, points] of Object.entries(data.series[kind] || {})) {
      if (points.length && topic !== settings.goal_topic) sources.push({ topic, kind, points });
    }
  }
  const rank = (s) => (s.topic === settings.pose_topic ? 0 : s.kind === 'pose' ? 1 : 2);
  return sources.sort((a, b) => rank(a) - rank(b));
}

// els: { section, select, poseSelect, stage, canvas, robot, goal, message, scalebar }.
export function createLiveMap(data, settings, els) {
  const sources = poseSources(data, settings);
  const maps = settings.maps || [];
  if (!maps.length || !sources.length) {
    els.message.textContent = !maps.length
      ? _('No floorplan to draw on: ROVER_WEB_MAPS_FILE lists none.')
      : _('No pose in this recording (%(topic)s was not recorded, nor any odometry).', { topic: settings.pose_topic });
    els.stage.hidden = true;
    return { show() {} };
  }
  const goals = (data.series.pose || {})[settings.goal_topic] || [];
  const plans = (data.series.plan || {})[settings.plan_topic] || [];
  const ctx = els.canvas.getContext('2d');
  const S = {
    geometry: null, view: { scale: 1, ox: 0, oy: 0 }, size: { width: 0, height: 0 }, fitted: false, tracking: false,
    mode: 'pan', gesture: null, preview: null, cursor: null, pose: null, goal: null, plan: null, waypoints: [],
    keepOut: [], botRadiusM: settings.bot_diameter_cm / 200, source: sources[0], t: data.start, drawn: null,
  };
  const image = new Image();
  image.decoding = 'async';
  let imageLoaded = false;
  let pending = false;

  function draw() {
    pending = false;
    if (!S.geometry) return;
    const dpr = window.devicePixelRatio || 1;
    S.drawn = drawScene(ctx, {
      image: imageLoaded ? image : null, geometry: S.geometry, view: S.view, size: S.size, dpr, plan: S.plan,
      waypoints: S.waypoints, goal: S.goal, pose: S.pose, poseStale: S.pose ? S.pose.stale : true, preview: null,
      botRadiusM: S.botRadiusM, keepOut: S.keepOut,
    });
    const bar = scaleBar(S.geometry, S.view);
    els.scalebar.querySelector('span').style.width = `${bar.widthPx}px`;
    els.scalebar.querySelector('b').textContent = bar.label;
    window.replayLiveMap = { geometry: { ...S.geometry }, view: { ...S.view }, dpr, imageLoaded, t: S.t,
      source: S.source.topic, ...S.drawn };
  }
  const redraw = () => { if (!pending) { pending = true; requestAnimationFrame(draw); } };
  const viewport = createViewport(S, redraw);

  function resize() {
    const rect = els.stage.getBoundingClientRect();
    const width = Math.max(1, Math.floor(rect.width));
    const height = Math.max(1, Math.floor(rect.height));
    const dpr = window.devicePixelRatio || 1;
    if (S.geometry) viewport.resize(width, height); else S.size = { width, height };
    els.canvas.width = Math.round(width * dpr);
    els.canvas.height = Math.round(height * dpr);
    els.canvas.style.width = `${width}px`;
    els.canvas.style.height = `${height}px`;
    draw();
  }

  async function loadMap(name) {
    const summary = maps.find((m) => m.name === name) || maps[0];
    els.section.dataset.ready = 'no';
    try {
      // A GET of the map's state, as the LiveMap page renders it (its live pose is not used here).
      const state = await api('GET', `/api/maps/${encodeURIComponent(summary.name)}`);
      const params = state.map_parameters;
      S.geometry = geometryOf(params);
      S.waypoints = params.waypoints || [];
      S.keepOut = summary.keep_out || [];
      S.fitted = false;
      imageLoaded = false;
      image.onload = () => { imageLoaded = true; els.section.dataset.ready = 'yes'; redraw(); };
      image.src = summary.urls.image;  // already under the page's robot prefix
      resize();  // measures the stage and fits the new map in it
      els.message.textContent = '';
    } catch (err) {
      els.message.textContent = _('The floorplan %(map)s could not be read: %(reason)s', { map: summary.label, reason: err.message });
    }
  }

  function show(t) {
    S.t = t;
    const p = lastAtOrBefore(S.source.points, t);
    const staleAfter = settings.pose_stale_s;
    S.pose = p ? { x: p.x, y: p.y, yaw: p.yaw, frame_id: p.frame_id, stale: staleAfter > 0 && t - p.t > staleAfter } : null;
    const g = lastAtOrBefore(goals, t);
    S.goal = g ? { x: g.x, y: g.y, yaw: g.yaw, frame_id: g.frame_id } : null;
    const plan = lastAtOrBefore(plans, t);
    S.plan = plan ? { points: plan.points, length: plan.length, frame_id: plan.frame_id } : null;
    els.robot.textContent = S.pose
      ? `${metres(S.pose.x, S.pose.y)} · ${degrees(S.pose.yaw)}${S.pose.stale ? ` ${_('(stale)')}` : ''}` : '—';
    els.goal.textContent = S.goal ? `${metres(S.goal.x, S.goal.y)} · ${degrees(S.goal.yaw)}` : '—';
    redraw();
  }

  els.poseSelect.replaceChildren(...sources.map((s, i) => Object.assign(document.createElement('option'), {
    value: String(i), textContent: s.kind === 'odom' ? _('%(topic)s (odometry: its frame drawn as the map’s)', { topic: s.topic }) : s.topic,
  })));
  els.poseSelect.addEventListener('change', () => { S.source = sources[Number(els.poseSelect.value)]; show(S.t); });
  els.select.replaceChildren(...maps.map((m) => Object.assign(document.createElement('option'), {
    value: m.name, textContent: m.label, selected: m.name === settings.default_map })));
  els.select.addEventListener('change', () => loadMap(els.select.value));
  // Pan and zoom as on the LiveMap page; its goal gestures have nothing to send here.
  const nothing = () => {};
  attachInput(els.canvas, S, { viewport, redraw, setMode: nothing, stopTracking: nothing, sendGoal: nothing,
    livePose: () => null });
  new ResizeObserver(resize).observe(els.stage);
  loadMap(els.select.value).then(() => show(S.t));
  return { show };
}
