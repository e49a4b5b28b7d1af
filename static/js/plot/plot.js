// Live plots: the operator adds (topic, field) series; each starts with its recent history from
// GET /api/plot and then grows from the `plot` channel (new points of every series, ten times a
// second). All series share one time axis (uPlot.join aligns them). Pause freezes the chart, a
// drag zooms (and pauses), CSV exports every point this page holds.
import { api, ApiError } from '../core/api.js';
import { on } from '../live/live.js';
import { chartWidth, joined, makeChart, seriesItems } from './chart.js';
import { _ } from '../core/i18n.js';

const KEEP = 20000;  // points per series kept in the page
const $ = (id) => document.getElementById(id);
const chartEl = $('plot-chart');
const topicSelect = $('plot-topic');
const fieldInput = $('plot-field');
const pauseButton = $('plot-pause');
const idleS = Number($('plot').dataset.idleS || 30);

const series = new Map();  // id -> {topic, field, t: [], v: []}
let chart = null;
let paused = false;
let drawPending = false;

function showError(err) {
  const el = $('plot-error');
  if (!err) { el.hidden = true; return; }
  el.textContent = err instanceof ApiError ? err.message : _('the server was not reached');
  el.hidden = false;
}

// A type the server will not plot (422 not_plottable: images, point clouds, maps) is said beside
// the field chooser, in the server's words, for as long as that topic is chosen.
function showRefusal(err) {
  const el = $('plot-refusal');
  const refused = err instanceof ApiError && err.status === 422;
  el.textContent = refused ? err.message : '';
  el.dataset.code = refused ? err.code || '' : '';
  el.hidden = !refused;
  if (refused) fieldInput.setAttribute('aria-describedby', 'plot-refusal');
  else fieldInput.removeAttribute('aria-describedby');
  fieldInput.setAttribute('aria-invalid', String(refused));
  return refused;
}

function showFailure(err) {
  if (showRefusal(err)) showError(null); else showError(err);
}

const windowS = () => Number($('plot-window').value);

function tables(since) {
  return [...series.values()].map((s) => {
    let i = 0;
    while (i < s.t.length && s.t[i] < since) i++;
    return [s.t.slice(i), s.v.slice(i)];
  });
}

function setPaused(value) {
  paused = value;
  pauseButton.setAttribute('aria-pressed', String(paused));
  pauseButton.textContent = paused ? _('Resume') : _('Pause');
  $('plot-state').textContent = paused ? _('paused') : _('live');
  if (!paused) rebuild();
}

function rebuild() {
  if (chart) { chart.destroy(); chart = null; }
  chartEl.replaceChildren();
  if (!series.size) { chartEl.dataset.points = '0'; return; }
  chart = makeChart(chartEl, [...series.keys()], data(), { onSelect: () => setPaused(true) });
}

function data() {
  const now = Date.now() / 1000;
  const aligned = joined(tables(now - windowS()));
  chartEl.dataset.points = String(aligned[0].length);
  return aligned;
}

function draw() {
  drawPending = false;
  if (paused || !chart) return;
  chart.setData(data());
}

function scheduleDraw() {
  if (!drawPending) { drawPending = true; requestAnimationFrame(draw); }
}

function renderList() {
  $('plot-empty').hidden = series.size > 0;  // what to do, until something is plotted
  $('plot-series').replaceChildren(...seriesItems([...series.keys()], (id) => { series.delete(id); renderList(); rebuild(); }));
}

function query(topic, field, seconds) {
  return new URLSearchParams({ topic, field, seconds: String(seconds) });
}

async function add(topic, field) {
  const reply = await api('GET', `/api/plot?${query(topic, field, windowS())}`);
  if (!series.has(reply.id)) {
    series.set(reply.id, { topic, field, t: reply.t, v: reply.v });
    renderList();
    rebuild();
  }
}

on('plot', (event) => {
  for (const [id, points] of Object.entries(event.series)) {
    const s = series.get(id);
    if (!s) continue;
    const last = s.t.length ? s.t[s.t.length - 1] : -Infinity;
    points.t.forEach((t, i) => { if (t > last) { s.t.push(t); s.v.push(points.v[i]); } });
    if (s.t.length > KEEP) { s.t.splice(0, s.t.length - KEEP); s.v.splice(0, s.v.length - KEEP); }
  }
  scheduleDraw();
});

function csv() {
  const all = joined(tables(-Infinity));
  const quote = (text) => `"${text.replaceAll('"', '""')}"`;
  const lines = [['time_unix_s', ...[...series.keys()].map(quote)].join(',')];
  for (let i = 0; i < all[0].length; i++) {
    lines.push(all.map((column) => (column[i] === null || column[i] === undefined ? '' : column[i])).join(','));
  }
  return `${lines.join('\n')}\n`;
}

$('plot-csv').addEventListener('click', () => {
  const url = URL.createObjectURL(new Blob([csv()], { type: 'text/csv' }));
  const a = document.createElement('a');
  a.href = url;
  a.download = `rover_web-plot-${new Date().toISOString().replaceAll(':', '-')}.csv`;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
});

async function loadFields() {
  $('plot-fields').replaceChildren();
  showRefusal(null);
  if (!topicSelect.value) return;
  try {
    const reply = await api('GET', `/api/plot/fields?${new URLSearchParams({ topic: topicSelect.value })}`);
    $('plot-fields').replaceChildren(...reply.fields.map((f) => Object.assign(document.createElement('option'), { value: f })));
    showError(null);
  } catch (err) { showFailure(err); }
}

topicSelect.addEventListener('change', loadFields);
$('plot-form').addEventListener('submit', async (e) => {
  e.preventDefault();
  const topic = topicSelect.value;
  const field = fieldInput.value.trim();
  if (!topic || !field) { showError(new ApiError(400, 'missing', _('choose a topic and a field'))); return; }
  try { await add(topic, field); showFailure(null); } catch (err) { showFailure(err); }
});
pauseButton.addEventListener('click', () => setPaused(!paused));
$('plot-window').addEventListener('change', () => { if (!paused) rebuild(); });

on('topics', (graph) => {
  const chosen = topicSelect.value;
  const options = graph.topics.filter((t) => t.types.length === 1).map((t) => {
    const o = document.createElement('option');
    o.value = t.name;
    o.textContent = `${t.name} (${t.types[0]})`;
    return o;
  });
  topicSelect.replaceChildren(Object.assign(document.createElement('option'), { value: '', textContent: 'choose a topic' }),
    ...options);
  topicSelect.value = chosen;
});

// The server ends a series nobody asked for in idle_s; an open page keeps its series alive.
setInterval(() => {
  for (const s of series.values()) api('GET', `/api/plot?${query(s.topic, s.field, 1)}`).catch(() => {});
}, (idleS * 1000) / 3);
window.addEventListener('resize', () => { if (chart) chart.setSize({ width: chartWidth(chartEl), height: 420 }); });

// /plot?topic=/odom&field=twist.twist.linear.x opens with that series.
const params = new URLSearchParams(location.search);
for (const field of params.getAll('field')) {
  const topic = params.get('topic');
  if (topic) add(topic, field).catch(showFailure);
}
