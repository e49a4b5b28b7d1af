// The replay view: a recording's GPS track on the waypoints map (or, without GPS, its odometry
// track on a canvas), its /rosout lines and its audit trail, on a time slider with play/pause and
// speed. Everything comes from one GET of the recording's timeline (decoded on the server); this
// page sends nothing to the robot and publishes nothing.
import { api } from '../api.js';
import { createGpsMap } from '../gps_map.js';

const $ = (id) => document.getElementById(id);
const id = $('replay').dataset.id;
const slider = $('replay-slider');
const playButton = $('replay-play');
const speed = $('replay-speed');
const canvas = $('replay-track');
const ctx = canvas.getContext('2d');
const SHOWN_LINES = 50;

let data = null;
let track = [];  // [{t, a, b}]: a, b are lng, lat (GPS) or x, y (odometry)
let gps = false;
let map = null;  // the MapLibre map, once loaded (GPS tracks only)
let now = 0;  // seconds since the recording's start
let playing = false;
let lastFrame = 0;

function chooseTrack(series) {
  const fix = Object.entries(series.fix || {})[0];
  if (fix) return { name: `${fix[0]} (GPS)`, gps: true, points: fix[1].map((p) => ({ t: p.t, a: p.lng, b: p.lat })) };
  const odom = Object.entries(series.odom || {})[0];
  if (odom) {
    return { name: `${odom[0]} (odometry)`, gps: false, points: odom[1].map((p) => ({ t: p.t, a: p.x, b: p.y })) };
  }
  return { name: 'no GPS or odometry in this recording', gps: false, points: [] };
}

function bounds(points) {
  const as = points.map((p) => p.a);
  const bs = points.map((p) => p.b);
  const pad = (lo, hi) => (hi - lo || 1e-6) * 0.05;
  const [a0, a1, b0, b1] = [Math.min(...as), Math.max(...as), Math.min(...bs), Math.max(...bs)];
  return { a0: a0 - pad(a0, a1), a1: a1 + pad(a0, a1), b0: b0 - pad(b0, b1), b1: b1 + pad(b0, b1) };
}

function toCanvas(box, p) {
  const scale = Math.min(canvas.width / (box.a1 - box.a0), canvas.height / (box.b1 - box.b0));
  return [(p.a - box.a0) * scale, canvas.height - (p.b - box.b0) * scale];
}

const line = (points) => ({ type: 'Feature', properties: {},
  geometry: { type: 'LineString', coordinates: points.map((p) => [p.a, p.b]) } });
const point = (p) => ({ type: 'FeatureCollection', features: p
  ? [{ type: 'Feature', properties: {}, geometry: { type: 'Point', coordinates: [p.a, p.b] } }] : [] });

function drawOnMap(t) {
  const past = track.filter((p) => p.t <= t);
  const here = past.length ? past[past.length - 1] : null;
  if (map) {
    map.getSource('replay-past').setData(line(past.length > 1 ? past : []));
    map.getSource('replay-here').setData(point(here));
  }
  return here;
}

function startMap() {
  const container = $('replay-map');
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
        show();
      } });
    window.roverReplayMap = created;  // for the browser tests and the curious operator's console
  } catch (err) {  // no WebGL: the canvas still shows the track
    container.hidden = true;
    gps = false;
  }
}

function drawTrack(t) {
  if (gps) return drawOnMap(t);
  canvas.hidden = false;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  if (!track.length) return null;
  const box = bounds(track);
  ctx.strokeStyle = '#bbb';
  ctx.beginPath();
  track.forEach((p, i) => { const [x, y] = toCanvas(box, p); if (i) ctx.lineTo(x, y); else ctx.moveTo(x, y); });
  ctx.stroke();
  const past = track.filter((p) => p.t <= t);
  if (!past.length) return null;
  ctx.strokeStyle = '#1565c0';
  ctx.lineWidth = 2;
  ctx.beginPath();
  past.forEach((p, i) => { const [x, y] = toCanvas(box, p); if (i) ctx.lineTo(x, y); else ctx.moveTo(x, y); });
  ctx.stroke();
  ctx.lineWidth = 1;
  const here = past[past.length - 1];
  const [x, y] = toCanvas(box, here);
  ctx.fillStyle = '#b00020';
  ctx.beginPath();
  ctx.arc(x, y, 5, 0, 2 * Math.PI);
  ctx.fill();
  return here;
}

function clock(t) {
  return new Date(t * 1000).toLocaleTimeString();
}

function fillList(list, items, text) {
  list.replaceChildren(...items.slice(-SHOWN_LINES).reverse().map((item) => {
    const li = document.createElement('li');
    li.textContent = `${clock(item.t)} ${text(item)}`;
    return li;
  }));
}

function show() {
  const t = data.start + now;
  const span = data.end - data.start;
  slider.value = span > 0 ? Math.round((now / span) * 1000) : 0;
  $('replay-time').textContent = `${clock(t)} (+${now.toFixed(1)} s of ${span.toFixed(1)} s)`;
  const here = drawTrack(t);
  $('replay-position').textContent = here ? `at ${here.b.toFixed(6)}, ${here.a.toFixed(6)}` : '';
  fillList($('replay-audit'), data.audit.filter((r) => r.t <= t), (r) => `${r.by || '?'}: ${r.detail || r.action}`);
  fillList($('replay-logs'), data.logs.filter((l) => l.t <= t), (l) => `[${l.level}] ${l.name}: ${l.msg}`);
}

function frame(stamp) {
  if (!playing) return;
  const dt = lastFrame ? (stamp - lastFrame) / 1000 : 0;
  lastFrame = stamp;
  now = Math.min(data.end - data.start, now + dt * Number(speed.value));
  show();
  if (now >= data.end - data.start) setPlaying(false);
  else requestAnimationFrame(frame);
}

function setPlaying(on) {
  playing = on;
  playButton.textContent = on ? 'Pause' : 'Play';
  playButton.setAttribute('aria-pressed', String(on));
  lastFrame = 0;
  if (on) requestAnimationFrame(frame);
}

playButton.addEventListener('click', () => {
  if (!data) return;
  if (!playing && now >= data.end - data.start) now = 0;
  setPlaying(!playing);
});

slider.addEventListener('input', () => {
  if (!data) return;
  now = (Number(slider.value) / 1000) * (data.end - data.start);
  show();
});

async function load() {
  try {
    data = await api('GET', `/api/recordings/${id}/timeline`);
  } catch (err) {
    $('replay-error').hidden = false;
    $('replay-error').textContent = err.message;
    return;
  }
  if (data.start === null) {
    $('replay-time').textContent = 'this recording holds no message';
    return;
  }
  const chosen = chooseTrack(data.series);
  track = chosen.points;
  gps = chosen.gps;
  $('replay-track-name').textContent = chosen.name;
  if (gps) startMap();
  show();
}

load();
