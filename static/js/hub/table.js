// The hub's table of robots (templates/hub.html): sortable by any column (a header's button; again
// to reverse), filtered by what the operator types (name, title, state, mode, link, alerts), so a
// fleet of a hundred robots stays readable. Rows are rebuilt on every poll; the order and the filter
// are the page's, kept across polls. Untrusted text goes through textContent only.
import { ESTOP_WORDS, LINK_WORDS, MODE_WORDS, estopState } from '../fleet/map.js';
import { EVENT_WORDS } from './history.js';
import { _, ngettext, formatUnit, saidWire } from '../core/i18n.js';

const ORDER = { live: 0, waiting: 1, lost: 2 };

function sortValue(r, key) {
  switch (key) {
    case 'heard': return ORDER[r.heard] ?? 3;
    case 'battery': return r.battery && r.battery.percent != null ? r.battery.percent : Infinity;
    case 'estop': return estopState(r);
    case 'position': return r.position ? r.position.lat : Infinity;
    case 'alerts': return -(r.alerts || []).length;
    case 'title': return String(r.title || r.name).toLowerCase();
    default: return String(r[key] ?? '');
  }
}

// A robot's alerts in this page's language (the robot sends each one's id and values beside its English).
function alertTexts(r) {
  const wires = Array.isArray(r.alerts_i18n) ? r.alerts_i18n : [];
  return (r.alerts || []).map((english, i) => saidWire(english, wires[i]));
}

function cell(text) {
  const td = document.createElement('td');
  td.textContent = text;
  return td;
}

function row(r) {
  const tr = document.createElement('tr');
  tr.dataset.robot = r.name;
  tr.dataset.heard = r.heard;
  const name = document.createElement('td');
  if (r.url) {
    const a = document.createElement('a');
    a.href = r.url;
    a.textContent = r.title;
    name.append(a);
  } else {
    name.textContent = r.title;
  }
  const heard = cell(EVENT_WORDS[r.heard] || r.heard);
  if (r.forget_in_s != null) {
    const note = document.createElement('span');
    note.className = 'muted';
    note.textContent = ` ${_('(dropped in %(time)s)', { time: formatUnit(r.forget_in_s, 's') })}`;
    heard.append(note);
  }
  const battery = r.battery && r.battery.percent != null ? formatUnit(r.battery.percent, '%', 0) : '—';
  // Coordinates keep the dot whatever the language: they are read into other tools as they are.
  const position = r.position ? `${r.position.lat.toFixed(6)}, ${r.position.lng.toFixed(6)}` : '—';
  const estop = estopState(r);
  const history = document.createElement('td');
  const open = document.createElement('button');
  open.type = 'button';
  open.className = 'hub-history-open';
  open.dataset.robot = r.name;
  open.textContent = _('history');
  history.append(open);
  tr.append(name, heard, cell(LINK_WORDS[r.link] || r.link), cell(r.mode ? MODE_WORDS[r.mode] || r.mode : '—'), cell(battery),
            cell(estop === 'unknown' ? '—' : ESTOP_WORDS[estop]),
            cell(position), cell(alertTexts(r).join('; ')), history);
  return tr;
}

export function createTable(table, filterInput, counts) {
  const body = table.querySelector('tbody');
  let key = 'title';
  let direction = 1;
  let latest = [];

  function matches(r, needle) {
    if (!needle) return true;
    return [r.name, r.title, r.heard, r.mode, r.link, ...(r.alerts || []), ...alertTexts(r)]
      .some((v) => typeof v === 'string' && v.toLowerCase().includes(needle));
  }

  function render(robots) {
    latest = robots;
    const needle = filterInput.value.trim().toLowerCase();
    const shown = robots.filter((r) => matches(r, needle)).sort((a, b) => {
      const x = sortValue(a, key);
      const y = sortValue(b, key);
      return (x < y ? -1 : x > y ? 1 : a.name < b.name ? -1 : 1) * direction;
    });
    body.replaceChildren(...shown.map(row));
    const by = { live: 0, waiting: 0, lost: 0 };
    for (const r of robots) by[r.heard] = (by[r.heard] || 0) + 1;
    counts.textContent = ngettext('%(num)d robot: %(live)d live, %(waiting)d waiting, %(lost)d lost',
      '%(num)d robots: %(live)d live, %(waiting)d waiting, %(lost)d lost', robots.length, by)
      + (shown.length < robots.length ? ` · ${_('%(shown)d shown', { shown: shown.length })}` : '');
  }

  for (const button of table.querySelectorAll('button.hub-sort')) {
    button.addEventListener('click', () => {
      direction = key === button.dataset.sort ? -direction : 1;
      key = button.dataset.sort;
      for (const th of table.querySelectorAll('th[aria-sort]')) th.setAttribute('aria-sort', 'none');
      button.parentElement.setAttribute('aria-sort', direction > 0 ? 'ascending' : 'descending');
      render(latest);
    });
  }
  filterInput.addEventListener('input', () => render(latest));
  return { render };
}
