// The fleet page (/robots): every robot's state in the table and on one GPS map, kept current by
// asking GET /api/robots about once a second. Polling, not each robot's event stream: one small
// request covers every robot, where a stream per robot would hold one HTTP/1.1 connection each,
// and the browser allows only 6 per host — with a few robots the page's own requests (and every
// other rover_web tab) would queue behind them. A hidden tab stops asking until it is shown again.
// Untrusted text (titles, operator names) only ever goes through textContent.
import { api } from '../core/api.js';
import { ESTOP_WORDS, LINK_WORDS, MODE_WORDS, createFleetMap, estopState } from './map.js';
import { _, formatUnit } from '../core/i18n.js';

const POLL_MS = 1000;
const $ = (id) => document.getElementById(id);
const table = $('fleet-table');
const note = $('fleet-note');
const NOTE = note.textContent;
let timer = null;
let busy = false;

const fmt = {
  link: (r) => LINK_WORDS[r.link] || r.link.replace('_', ' '),
  mode: (r) => {
    const mode = MODE_WORDS[r.mode] || r.mode;
    return r.operator ? _('%(mode)s (%(operator)s)', { mode, operator: r.operator }) : mode;
  },
  speed: (r) => (r.speed ? formatUnit(r.speed.linear_mps, 'm/s', 2) : '—'),
  battery: (r) => {
    const b = r.battery;
    if (!b || (b.percent === null && b.voltage === null)) return '—';
    const percent = b.percent === null ? '—' : formatUnit(b.percent, '%', 0);
    return b.voltage === null ? percent : `${percent} · ${formatUnit(b.voltage, 'V', 2)}`;
  },
  estop: (r) => ESTOP_WORDS[estopState(r)],
  // Coordinates keep the dot whatever the language: they are read into other tools as they are.
  position: (r) => (r.position ? `${r.position.lat.toFixed(6)}, ${r.position.lng.toFixed(6)}` : '—'),
};

function cell(row, field) {
  let td = row.querySelector(`[data-field="${field}"]`);
  if (!td) {
    td = document.createElement('td');
    td.dataset.field = field;
    row.append(td);
  }
  return td;
}

function rowFor(robot) {
  let row = [...table.tBodies[0].rows].find((tr) => tr.dataset.robot === robot.name);
  if (!row) {
    row = document.createElement('tr');
    row.dataset.robot = robot.name;
    const name = document.createElement('td');
    const link = document.createElement('a');
    link.dataset.field = 'name';
    name.append(link);
    row.append(name);
    table.tBodies[0].append(row);
  }
  return row;
}

function renderRow(robot) {
  const row = rowFor(robot);
  row.dataset.estop = estopState(robot);
  row.dataset.link = robot.link;
  const link = row.querySelector('[data-field="name"]');
  link.href = robot.url;
  link.textContent = robot.title;
  let pill = cell(row, 'link').querySelector('.pill');
  if (!pill) {
    pill = document.createElement('span');
    pill.className = 'pill';
    cell(row, 'link').replaceChildren(pill);
  }
  pill.dataset.state = robot.link;
  pill.textContent = fmt.link(robot);
  for (const field of ['mode', 'speed', 'battery', 'estop', 'position']) cell(row, field).textContent = fmt[field](robot);
}

// --- polling ---

function render(state) {
  for (const robot of state.robots) renderRow(robot);
  table.dataset.updated = String(Number(table.dataset.updated) + 1);
  if (fleetMap) fleetMap.render(state.robots);
}

let latest = JSON.parse($('fleet-state').textContent);

async function poll() {
  timer = null;
  if (document.hidden || busy) return;
  busy = true;
  try {
    latest = await api('GET', '/api/robots');
    render(latest);
    table.dataset.stale = 'no';
    note.textContent = NOTE;
  } catch (err) {
    table.dataset.stale = 'yes';
    note.textContent = _('Not updated: %(reason)s', { reason: err.message });
  } finally {
    busy = false;
    if (!document.hidden) timer = setTimeout(poll, POLL_MS);
  }
}

document.addEventListener('visibilitychange', () => {
  clearTimeout(timer);
  timer = null;
  if (!document.hidden) poll();
});

// The markers and their framing are static/js/fleet/map.js's, shared with the hub's page.
const fleetMap = createFleetMap($('fleet-map'), $('fleet-map-note'));
render(latest);
timer = setTimeout(poll, POLL_MS);
