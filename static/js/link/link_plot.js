// The link plot on the dashboard's Node card: each second (on the `status` heartbeat) the browser
// times a GET /api/ping (browser↔server round trip) and reads the age of the newest message on
// the link topics from the status; both are plotted in ms over the last 5 minutes (log scale: a
// 3 ms round trip and a 4 s silence both stay readable).
import { at } from '../core/api.js';
import { on } from '../live/live.js';
import { loadUplot } from '../core/vendor.js';
import { _ } from '../core/i18n.js';
import { onThemeChange, plotAxes, seriesColour } from '../core/theme.js';

const KEEP = 300;
const el = document.getElementById('link-plot');
const t = [];
const rtt = [];
const age = [];
let chart = null;
let pinging = false;

function draw() {
  if (!window.uPlot || !el) return;
  if (!chart) {
    chart = new window.uPlot({
      width: Math.max(240, el.clientWidth), height: 160,
      scales: { ms: { distr: 3 } },
      series: [{}, { label: _('round trip ms'), scale: 'ms', stroke: () => seriesColour(0), spanGaps: false },
        { label: _('robot msg age ms'), scale: 'ms', stroke: () => seriesColour(1), spanGaps: false }],
      axes: plotAxes(50).map((axis, i) => (i === 1 ? { ...axis, scale: 'ms' } : axis)),
      legend: { live: false },
    }, [t, rtt, age], el);
  } else {
    chart.setData([t, rtt, age]);
  }
}

onThemeChange(() => { if (chart) chart.redraw(false, true); });

function push(rttMs, ageMs) {
  t.push(Date.now() / 1000);
  rtt.push(rttMs);
  age.push(ageMs);
  if (t.length > KEEP) { t.shift(); rtt.shift(); age.shift(); }
  el.dataset.rttMs = rttMs === null ? '' : rttMs.toFixed(1);
  el.dataset.ageMs = ageMs === null ? '' : ageMs.toFixed(0);
  el.dataset.points = String(t.length);
  draw();
}

function newestAgeMs(status) {
  const ages = status.topics.filter((x) => status.link_topics.includes(x.topic) && x.age_s !== null)
    .map((x) => x.age_s * 1000);
  return ages.length ? Math.max(0.1, Math.min(...ages)) : null;
}

// uPlot comes after the page is live (core/vendor.js); the points gathered until then are drawn then.
if (el) loadUplot().then(draw, () => {});

on('status', async (status) => {
  if (!el || pinging || document.hidden) return;
  pinging = true;
  let rttMs = null;
  try {
    const start = performance.now();
    const response = await fetch(at('/api/ping'), { cache: 'no-store' });
    await response.arrayBuffer();
    if (response.ok) rttMs = Math.max(0.1, performance.now() - start);
  } catch { /* not reached: a gap in the line */ }
  pinging = false;
  push(rttMs, newestAgeMs(status));
});
