// Plot cards (templates/cards/plot.html): the series a layout names, each starting with its recent
// history from GET /api/plot and growing from the `plot` channel, as on the Plot page (plot.js,
// which adds series interactively; a card's are fixed by its settings). The server ends a series
// nobody asked for in a while, so an open card asks again now and then.
import { api, ApiError } from '../core/api.js';
import { on } from '../live/live.js';
import { loadUplot } from '../core/vendor.js';
import { _ } from '../core/i18n.js';
import { onThemeChange, plotAxes, seriesColour } from '../core/theme.js';

const KEEP_ALIVE_MS = 10000;
const HEIGHT = 200;

const cards = [...document.querySelectorAll('[data-plot-card]')].map((el) => ({
  el,
  chartEl: el.querySelector('.plot-card-chart'),
  windowS: Number(el.dataset.windowS) || 30,
  series: [...el.querySelectorAll('[data-topic]')].map((li) => ({ topic: li.dataset.topic, field: li.dataset.field,
    id: null, t: [], v: [] })),
  chart: null,
}));

const query = (s, seconds) => new URLSearchParams({ topic: s.topic, field: s.field, seconds: String(seconds) });

function showError(card, err) {
  const el = card.el.querySelector('.plot-card-error');
  el.textContent = err ? (err instanceof ApiError ? err.message : _('the server was not reached')) : '';
  el.hidden = !err;
}

function data(card) {
  const since = Date.now() / 1000 - card.windowS;
  const tables = card.series.filter((s) => s.id).map((s) => {
    let i = 0;
    while (i < s.t.length && s.t[i] < since) i++;
    s.t.splice(0, i);
    s.v.splice(0, i);
    return [s.t, s.v];
  });
  const joined = tables.length ? window.uPlot.join(tables) : [[]];
  card.chartEl.dataset.points = String(joined[0].length);
  return joined;
}

function draw(card) {
  if (!window.uPlot) return;
  const width = Math.max(200, card.chartEl.clientWidth);
  if (!card.chart) {
    const shown = card.series.filter((s) => s.id);
    if (!shown.length) return;
    card.chart = new window.uPlot({
      width, height: HEIGHT, legend: { live: false },
      series: [{}, ...shown.map((s, i) => ({ label: s.field, stroke: () => seriesColour(i), spanGaps: true }))],
      axes: plotAxes(50),
    }, data(card), card.chartEl);
  } else {
    card.chart.setData(data(card));
  }
}

async function start(card) {
  for (const s of card.series) {
    try {
      const reply = await api('GET', `/api/plot?${query(s, card.windowS)}`);
      Object.assign(s, { id: reply.id, t: reply.t, v: reply.v });
      showError(card, null);
    } catch (err) { showError(card, err); }
  }
  if (card.chart) { card.chart.destroy(); card.chart = null; }
  draw(card);
}

if (cards.length) {
  let pending = false;
  on('plot', (event) => {
    for (const card of cards) {
      for (const s of card.series) {
        const points = s.id && event.series[s.id];
        if (!points) continue;
        const last = s.t.length ? s.t[s.t.length - 1] : -Infinity;
        points.t.forEach((t, i) => { if (t > last) { s.t.push(t); s.v.push(points.v[i]); } });
      }
    }
    if (!pending) {
      pending = true;
      requestAnimationFrame(() => { pending = false; cards.forEach(draw); });
    }
  });
  cards.forEach(start);
  // uPlot comes after the page is live (core/vendor.js); what came before is drawn then.
  loadUplot().then(() => cards.forEach(draw), (err) => cards.forEach((card) => showError(card, err)));
  setInterval(() => {
    for (const card of cards) for (const s of card.series) api('GET', `/api/plot?${query(s, 1)}`).catch(() => {});
  }, KEEP_ALIVE_MS);
  onThemeChange(() => { for (const card of cards) if (card.chart) card.chart.redraw(false, true); });
  window.addEventListener('resize', () => {
    for (const card of cards) if (card.chart) card.chart.setSize({ width: Math.max(200, card.chartEl.clientWidth), height: HEIGHT });
  });
}
