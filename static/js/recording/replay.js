// The replay view: a recording's GPS (or odometry) track, its /rosout lines and its audit trail,
// on a time slider with play/pause and speed. Everything comes from one GET of the recording's
// timeline (decoded on the server); this page sends nothing to the robot and publishes nothing.
import { api } from '../api.js';

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
let now = 0;  // seconds since the recording's start
let playing = false;
let lastFrame = 0;

function chooseTrack(series) {
  const fix = Object.entries(series.fix || {})[0];
  if (fix) return { name: `${fix[0]} (GPS)`, points: fix[1].map((p) => ({ t: p.t, a: p.lng, b: p.lat })) };
  const odom = Object.entries(series.odom || {})[0];
  if (odom) return { name: `${odom[0]} (odometry)`, points: odom[1].map((p) => ({ t: p.t, a: p.x, b: p.y })) };
  return { name: 'no GPS or odometry in this recording', points: [] };
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

function drawTrack(t) {
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
  $('replay-track-name').textContent = chosen.name;
  show();
}

load();
