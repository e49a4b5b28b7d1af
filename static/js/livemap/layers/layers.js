// What the robot senses, as layers over the floorplan: costmaps under everything, then the recent
// path, the footprint, markers and the laser scan. Each layer is switched on and off by its
// checkbox (remembered in this browser), and keeps only its newest value from the event stream;
// drawing happens in the page's one animation frame (livemap.js), never on arrival.
import { api } from '../../core/api.js';
import { on } from '../../live/live.js';
import { drawCostmap, renderCostmap } from './costmap.js';
import { drawFootprint, drawMarker, drawPath, drawScan } from './shapes.js';
import { _, ngettext, formatNumber } from '../../core/i18n.js';

const STORAGE_KEY = 'rover_web.livemap.layers';
const OPACITY_KEY = 'rover_web.livemap.costmap_opacity';
const COUNTS_EVERY_MS = 2000;
const TRAIL_MAX_POINTS = 2000;
const TRAIL_STEP_M = 0.05;
// What placed a layer's latest message on the map (the server's `placed_by`).
const PLACED_LABELS = {
  tf: _('placed by TF'), configured: _('placed by configured offsets'), map: _('in the map frame'), amcl: _('placed by AMCL'),
};

function showPlaced(el, how) {
  if (!el || !how || el.dataset.placed === how) return;
  el.dataset.placed = how;
  el.textContent = PLACED_LABELS[how] || how;
}

function remembered() {
  try { return JSON.parse(localStorage.getItem(STORAGE_KEY) || '{}') || {}; } catch { return {}; }
}

// panel: the side panel's layer list (the partial livemap_layers.html); redraw(): ask for a frame.
export function createLayers(panel, redraw) {
  const shown = { scan: true, costmap: true, markers: true, footprint: true, path: true, ...remembered() };
  const L = { scan: null, costmaps: new Map(), markers: [], footprint: null, trail: [], opacity: 0.6 };
  const storedOpacity = Number(localStorage.getItem(OPACITY_KEY));
  if (storedOpacity > 0 && storedOpacity <= 1) L.opacity = storedOpacity;

  for (const box of panel ? panel.querySelectorAll('input[data-layer]') : []) {
    box.checked = shown[box.dataset.layer] !== false;
    box.addEventListener('change', () => {
      shown[box.dataset.layer] = box.checked;
      localStorage.setItem(STORAGE_KEY, JSON.stringify(shown));
      redraw();
    });
  }
  const slider = panel && panel.querySelector('#overlay-costmap-opacity');
  if (slider) {
    slider.value = String(Math.round(L.opacity * 100));
    slider.addEventListener('input', () => {
      L.opacity = Number(slider.value) / 100;
      localStorage.setItem(OPACITY_KEY, String(L.opacity));
      redraw();
    });
  }

  const placedEl = (name) => document.getElementById(`overlay-placed-${name}`);
  on('scan', (scan) => { L.scan = scan; showPlaced(placedEl('scan'), scan.placed_by); redraw(); });
  on('markers', (m) => { L.markers = m.markers; redraw(); });
  on('footprint', (f) => { L.footprint = f; showPlaced(placedEl('footprint'), f.placed_by); redraw(); });
  // A grid is decoded only when it is new (its seq changed); the others keep their canvases.
  function decode(layer) {
    renderCostmap(layer).then((canvas) => {
      const current = L.costmaps.get(layer.topic);
      if (current && current.layer.seq >= layer.seq) return;  // a newer one was decoded first
      L.costmaps.set(layer.topic, { layer, canvas });
      redraw();
    }).catch((err) => console.warn(err.message));
  }
  // The channel carries only the cells of the grids that changed; a grid this page has never had
  // (it opened after that grid last changed) is read from the API, once however many events ask.
  let fetching = null;
  function fetchCostmaps() {
    if (fetching) return;
    fetching = api('GET', '/api/overlays?costmaps=1')
      .then((summary) => { for (const layer of summary.costmaps) decode(layer); })
      .catch(() => { /* the next event asks again */ })
      .finally(() => { fetching = null; });
  }
  on('costmap', (c) => {
    const topics = new Set(c.costmaps.map((layer) => layer.topic));
    for (const topic of [...L.costmaps.keys()]) if (!topics.has(topic)) L.costmaps.delete(topic);
    for (const layer of c.costmaps) {
      const known = L.costmaps.get(layer.topic);
      if (known && known.layer.seq >= layer.seq) continue;
      if (layer.data === null) fetchCostmaps(); else decode(layer);
    }
  });
  on('pose', (p) => {
    const robot = document.getElementById('livemap-robot-placed');
    if (robot && p.placed_by && robot.dataset.placed !== p.placed_by) {
      robot.dataset.placed = p.placed_by;
      robot.textContent = _('Robot: %(placed)s', { placed: PLACED_LABELS[p.placed_by] || p.placed_by });
    }
    if (p.stale) return;
    const last = L.trail[L.trail.length - 1];
    if (last && Math.hypot(p.x - last[0], p.y - last[1]) < TRAIL_STEP_M) return;
    L.trail.push([p.x, p.y]);
    if (L.trail.length > TRAIL_MAX_POINTS) L.trail.splice(0, L.trail.length - TRAIL_MAX_POINTS);
  });

  // Counts of what was received and skipped come from the API, while the page is visible.
  async function refreshCounts(first) {
    if (document.hidden && !first) return;
    try {
      const summary = await api('GET', '/api/overlays');
      if (first) L.trail = summary.trail.concat(L.trail);
      for (const [name, c] of Object.entries(summary.layers)) {
        const el = document.getElementById(`overlay-skipped-${name}`);
        if (el) el.textContent = c.skipped ? _('%(num)d skipped', { num: c.skipped }) : '';
        const reasons = Object.entries(c.skipped_by_reason).map(([k, v]) => `${k}: ${formatNumber(v)}`);
        if (c.dropped_items) {
          reasons.push(name === 'scan' ? ngettext('%(num)d beam without a return', '%(num)d beams without a return', c.dropped_items)
            : ngettext('%(num)d item left out', '%(num)d items left out', c.dropped_items));
        }
        const counted = _('%(received)d received, %(drawn)d drawn', { received: c.received, drawn: c.converted });
        if (el) el.title = reasons.length ? `${counted}; ${reasons.join(', ')}` : counted;
        showPlaced(placedEl(name), c.placed_by);
      }
      L.counts = summary.layers;
      redraw();
    } catch { /* the link pill says when the server is away */ }
  }
  refreshCounts(true);
  setInterval(() => refreshCounts(false), COUNTS_EVERY_MS);

  const state = () => ({
    shown: { ...shown }, opacity: L.opacity,
    scan: L.scan ? { points: L.scan.points.length / 2, far: (L.scan.far_points || []).length / 2, beams: L.scan.beams, placed_by: L.scan.placed_by } : null,
    costmaps: [...L.costmaps.values()].map(({ layer }) => ({ topic: layer.topic, seq: layer.seq, width: layer.width, height: layer.height })),
    markers: L.markers.length, footprint: L.footprint ? L.footprint.polygon.length : 0, trail: L.trail.length,
    counts: L.counts || null,
  });

  return {
    // Under the keep-out areas and the plan: the costmaps.
    drawUnder(ctx, { g, view, dpr }) {
      if (!shown.costmap) return;
      for (const { layer, canvas } of L.costmaps.values()) drawCostmap(ctx, g, view, dpr, layer, canvas, L.opacity);
    },
    // Over the plan, under the robot: path, footprint, markers, scan.
    drawOver(ctx, { toScreen, g, view }) {
      const pxPerM = view.scale / g.res;
      if (shown.path) drawPath(ctx, toScreen, L.trail);
      if (shown.footprint && L.footprint) drawFootprint(ctx, toScreen, L.footprint);
      if (shown.markers) for (const m of L.markers) drawMarker(ctx, toScreen, pxPerM, m);
      if (shown.scan && L.scan) drawScan(ctx, toScreen, L.scan);
    },
    state,
  };
}
