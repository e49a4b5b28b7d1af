// The replay's plots: chosen numeric fields of recorded topics over the whole recording, drawn by
// the plot page's chart (plot/chart.js) with a line at the slider's time, and each field's value
// at that time beside it. Fields and series come from the recording (GET .../fields, .../series),
// read and thinned on the server.
import { api, ApiError } from '../../core/api.js';
import { chartWidth, joined, makeChart, seriesItems } from '../../plot/chart.js';
import { lastIndexAtOrBefore } from './at.js';
import { _, formatNumber } from '../../core/i18n.js';

const HEIGHT = 280;
const NOT_PLOTTED = new Set(['sensor_msgs/msg/Image', 'sensor_msgs/msg/CompressedImage', 'sensor_msgs/msg/PointCloud2',
  'nav_msgs/msg/OccupancyGrid']);

// els: { topic, field, fields (datalist), form, list, chart, values, error }.
export function createPlots(recordingId, data, els) {
  const series = new Map();  // "topic field" -> { topic, field, t, v }
  let chart = null;
  let now = data.start;

  const say = (err) => {
    els.error.hidden = !err;
    els.error.textContent = err ? (err instanceof ApiError ? err.message : _('the server was not reached')) : '';
  };
  const url = (what, params) => `/api/recordings/${recordingId}/${what}?${params}`;

  function rebuild() {
    if (chart) { chart.destroy(); chart = null; }
    els.chart.replaceChildren();
    const all = joined([...series.values()].map((s) => [s.t, s.v]));
    els.chart.dataset.points = series.size ? String(all[0].length) : '0';
    if (series.size) chart = makeChart(els.chart, [...series.keys()], all, { height: HEIGHT, marker: () => now });
    renderList();
    showValues();
  }

  function renderList() {
    els.list.replaceChildren(...seriesItems([...series.keys()], (id) => { series.delete(id); rebuild(); }));
  }

  function showValues() {
    els.values.replaceChildren(...[...series.entries()].map(([id, s]) => {
      const i = lastIndexAtOrBefore(s.t, now, (t) => t);
      const value = i < 0 ? null : s.v[i];
      const li = document.createElement('li');
      li.dataset.series = id;
      li.textContent = `${id} = ${value === null ? '—' : formatNumber(Number(value.toPrecision(6)), { maximumSignificantDigits: 6 })}`;
      return li;
    }));
  }

  async function add(topic, field) {
    const id = `${topic} ${field}`;
    if (series.has(id)) return;
    const reply = await api('GET', url('series', new URLSearchParams({ topic, field })));
    series.set(id, { topic, field, t: reply.t, v: reply.v[field] });
    rebuild();
  }

  async function loadFields() {
    els.fields.replaceChildren();
    if (!els.topic.value) return;
    try {
      const reply = await api('GET', url('fields', new URLSearchParams({ topic: els.topic.value })));
      els.fields.replaceChildren(...reply.fields.map((f) => Object.assign(document.createElement('option'), { value: f })));
      say(null);
    } catch (err) { say(err); }
  }

  const topics = Object.entries(data.topics).filter(([, info]) => info.decodable && !NOT_PLOTTED.has(info.type));
  els.topic.replaceChildren(Object.assign(document.createElement('option'), { value: '', textContent: 'choose a topic' }),
    ...topics.map(([topic, info]) => Object.assign(document.createElement('option'), {
      value: topic, textContent: `${topic} (${info.type})` })));
  els.topic.addEventListener('change', loadFields);
  els.form.addEventListener('submit', async (event) => {
    event.preventDefault();
    const field = els.field.value.trim();
    if (!els.topic.value || !field) { say(new ApiError(400, 'missing', _('choose a topic and a field'))); return; }
    try { await add(els.topic.value, field); say(null); } catch (err) { say(err); }
  });
  window.addEventListener('resize', () => { if (chart) chart.setSize({ width: chartWidth(els.chart), height: HEIGHT }); });

  return {
    show(t) {
      now = t;
      if (chart) chart.redraw(false, false);  // the marker moves; the paths stay
      showValues();
    },
    add,
  };
}
