// The replay's track: the recording's GPS track on the waypoints map (MapLibre, with the offline
// basemap when one is installed) or, without GPS, its odometry track on a plain canvas; the past
// part drawn darker and the robot's place at the slider's time as a dot.
import { createGpsMap } from '../../gps/gps_map.js';
import { lastIndexAtOrBefore } from './at.js';
import { _ } from '../../core/i18n.js';

function chooseTrack(series) {
  const fix = Object.entries(series.fix || {}).find(([, points]) => points.length);
  if (fix) return { name: _('%(topic)s (GPS)', { topic: fix[0] }), gps: true, points: fix[1].map((p) => ({ t: p.t, a: p.lng, b: p.lat })) };
  const odom = Object.entries(series.odom || {}).find(([, points]) => points.length);
  if (odom) {
    return { name: _('%(topic)s (odometry)', { topic: odom[0] }), gps: false, points: odom[1].map((p) => ({ t: p.t, a: p.x, b: p.y })) };
  }
  return { name: _('no GPS or odometry in this recording'), gps: false, points: [] };
}

function bounds(points) {
  const as = points.map((p) => p.a);
  const bs = points.map((p) => p.b);
  const pad = (lo, hi) => (hi - lo || 1e-6) * 0.05;
  const [a0, a1, b0, b1] = [Math.min(...as), Math.max(...as), Math.min(...bs), Math.max(...bs)];
  return { a0: a0 - pad(a0, a1), a1: a1 + pad(a0, a1), b0: b0 - pad(b0, b1), b1: b1 + pad(b0, b1) };
}

const line = (points) => ({ type: 'Feature', properties: {},
  geometry: { type: 'LineString', coordinates: points.map((p) => [p.a, p.b]) } });
const point = (p) => ({ type: 'FeatureCollection', features: p
  ? [{ type: 'Feature', properties: {}, geometry: { type: 'Point', coordinates: [p.a, p.b] } }] : [] });

// els: { name, map, canvas, position }.
export function createTrack(data, els) {
  const chosen = chooseTrack(data.series);
  const track = chosen.points;
  let gps = chosen.gps;
  let map = null;  // the MapLibre map, once loaded (GPS tracks only)
  let lastT = data.start;
  const { canvas } = els;
  const ctx = canvas.getContext('2d');
  els.name.textContent = chosen.name;

  const past = (t) => track.slice(0, lastIndexAtOrBefore(track, t) + 1);

  function toCanvas(box, p) {
    const scale = Math.min(canvas.width / (box.a1 - box.a0), canvas.height / (box.b1 - box.b0));
    return [(p.a - box.a0) * scale, canvas.height - (p.b - box.b0) * scale];
  }

  function drawOnMap(t) {
    const before = past(t);
    const here = before.length ? before[before.length - 1] : null;
    if (map) {
      map.getSource('replay-past').setData(line(before.length > 1 ? before : []));
      map.getSource('replay-here').setData(point(here));
    }
    return here;
  }

  function startMap() {
    const container = els.map;
    container.hidden = false;
    const sources = {
      'replay-track': { type: 'geojson', data: line(track) },
      'replay-past': { type: 'geojson', data: line([]) },
      'replay-here': { type: 'geojson', data: point(null) },
    };
    const layers = [
      { id: 'replay-track', type: 'line', source: 'replay-track', paint: { 'line-color': '#9e9e9e', 'line-width': 2 } },
      { id: 'replay-past', type: 'line', source: 'replay-past', paint: { 'line-color': '#42a5f5', 'line-width': 3 } },
      { id: 'replay-here', type: 'circle', source: 'replay-here',
        paint: { 'circle-radius': 6, 'circle-color': '#e53935', 'circle-stroke-color': '#fff', 'circle-stroke-width': 2 } },
    ];
    try {
      const created = createGpsMap(container, JSON.parse(container.dataset.config), { sources, layers,
        onLoad: (loaded) => {
          map = loaded;
          const lngs = track.map((p) => p.a);
          const lats = track.map((p) => p.b);
          map.fitBounds([[Math.min(...lngs), Math.min(...lats)], [Math.max(...lngs), Math.max(...lats)]],
            { padding: 40, maxZoom: 19, duration: 0 });
          show(lastT);
        } });
      window.roverReplayMap = created;  // for the browser tests and the curious operator's console
    } catch (err) {  // no WebGL: the canvas still shows the track
      container.hidden = true;
      gps = false;
    }
  }

  function stroke(points, colour, width) {
    const box = bounds(track);
    ctx.strokeStyle = colour;
    ctx.lineWidth = width;
    ctx.beginPath();
    points.forEach((p, i) => { const [x, y] = toCanvas(box, p); if (i) ctx.lineTo(x, y); else ctx.moveTo(x, y); });
    ctx.stroke();
  }

  function drawOnCanvas(t) {
    canvas.hidden = false;
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    if (!track.length) return null;
    stroke(track, '#bbb', 1);
    const before = past(t);
    if (!before.length) return null;
    stroke(before, '#1565c0', 2);
    ctx.lineWidth = 1;
    const here = before[before.length - 1];
    const [x, y] = toCanvas(bounds(track), here);
    ctx.fillStyle = '#b00020';
    ctx.beginPath();
    ctx.arc(x, y, 5, 0, 2 * Math.PI);
    ctx.fill();
    return here;
  }

  function show(t) {
    lastT = t;
    const here = gps ? drawOnMap(t) : drawOnCanvas(t);
    // Coordinates keep the dot whatever the language: they are read into other tools as they are.
    els.position.textContent = here ? _('at %(position)s', { position: `${here.b.toFixed(6)}, ${here.a.toFixed(6)}` }) : '';
  }

  if (gps) startMap();
  return { show };
}
