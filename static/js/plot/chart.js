// The plot page's chart, shared with the replay view: uPlot (vendored, window.uPlot) with one time
// axis for every series (uPlot.join aligns them), the page's colours and axes. A drag across the
// chart selects (onSelect), a double click zooms out; `marker` draws a vertical line at a time.

import { _ } from '../core/i18n.js';
import { onThemeChange, plotAxes, seriesColour, themeColour } from '../core/theme.js';

// Colours are the theme's (static/css/app.css, --plot-*): read at each draw, so a chart follows a
// theme change (charts made here redraw on it).
const charts = new Set();
onThemeChange(() => charts.forEach((u) => u.redraw(false, true)));

export const chartWidth = (el) => Math.max(320, el.clientWidth);

// tables: one [t[], v[]] per series, in the order of `labels`.
export const joined = (tables) => window.uPlot.join(tables);

// labels: the series' names. options: { height, onSelect(u), marker() -> a time or null }.
export function makeChart(el, labels, data, { height = 420, onSelect = null, marker = null } = {}) {
  const hooks = {};
  if (onSelect) hooks.setSelect = [(u) => { if (u.select.width > 0) onSelect(u); }];
  if (marker) {
    hooks.draw = [(u) => {
      const t = marker();
      if (t === null || t === undefined) return;
      const x = u.valToPos(t, 'x', true);
      if (x < u.bbox.left || x > u.bbox.left + u.bbox.width) return;
      const { ctx } = u;
      ctx.save();
      ctx.strokeStyle = themeColour('--bad');
      ctx.lineWidth = 2 * (window.devicePixelRatio || 1);
      ctx.beginPath();
      ctx.moveTo(x, u.bbox.top);
      ctx.lineTo(x, u.bbox.top + u.bbox.height);
      ctx.stroke();
      ctx.restore();
    }];
  }
  const opts = {
    width: chartWidth(el), height,
    series: [{}, ...labels.map((label, i) => ({ label, stroke: () => seriesColour(i), spanGaps: true }))],
    axes: plotAxes(60),
    hooks,
  };
  hooks.destroy = [(u) => charts.delete(u)];
  const chart = new window.uPlot(opts, data, el);
  charts.add(chart);
  return chart;
}

// The list of plotted series, each with its × to remove it (the Plot page's and the replay's).
export function seriesItems(ids, onRemove) {
  return ids.map((id) => {
    const li = document.createElement('li');
    li.dataset.series = id;
    li.append(id);
    const remove = document.createElement('button');
    remove.type = 'button';
    remove.textContent = '×';
    remove.title = _('remove %(series)s', { series: id });
    remove.addEventListener('click', () => onRemove(id));
    li.append(remove);
    return li;
  });
}
