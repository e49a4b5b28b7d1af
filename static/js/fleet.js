// The fleet page (/robots): every robot's state in the table and on one GPS map, kept current by
// asking GET /api/robots about once a second. Polling, not each robot's event stream: one small
// request covers every robot, where a stream per robot would hold one HTTP/1.1 connection each,
// and the browser allows only 6 per host — with a few robots the page's own requests (and every
// other rover_web tab) would queue behind them. A hidden tab stops asking until it is shown again.
// Untrusted text (titles, operator names) only ever goes through textContent.
import { api } from './api.js';
import { createGpsMap, fmtLatLng } from './gps_map.js';

const POLL_MS = 1000;
const $ = (id) => document.getElementById(id);
const table = $('fleet-table');
const note = $('fleet-note');
const NOTE = note.textContent;
const markers = new Map();  // robot name -> maplibregl.Marker
let map = null;
let userMoved = false;  // once the operator pans or zooms, the map stops framing the robots itself
let framed = 0;         // how many robots had a position when the map last framed them
let timer = null;
let busy = false;

const fmt = {
  link: (r) => r.link.replace('_', ' '),
  mode: (r) => (r.operator ? `${r.mode} (${r.operator})` : r.mode),
  speed: (r) => (r.speed ? `${r.speed.linear_mps.toFixed(2)} m/s` : '—'),
  battery: (r) => {
    const b = r.battery;
    if (!b || (b.percent === null && b.voltage === null)) return '—';
    const percent = b.percent === null ? '—' : `${b.percent.toFixed(0)} %`;
    return b.voltage === null ? percent : `${percent} · ${b.voltage.toFixed(2)} V`;
  },
  estop: (r) => (r.estop.engaged ? 'engaged' : 'released'),
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
  row.dataset.estop = fmt.estop(robot);
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

// --- the map ---

function markerElement(robot) {
  const node = document.createElement('button');
  node.type = 'button';
  node.className = 'fleet-marker';
  node.dataset.robot = robot.name;
  const dot = document.createElement('span');
  dot.className = 'fleet-marker-dot';
  const name = document.createElement('span');
  name.className = 'fleet-marker-name';
  node.append(dot, name);
  // A marker is a link to its robot's dashboard, by mouse, touch or keyboard.
  node.addEventListener('click', (e) => {
    e.stopPropagation();
    window.location.assign(node.dataset.url);
  });
  return node;
}

function renderMarker(robot) {
  let marker = markers.get(robot.name);
  if (!robot.position) {
    // Kept where it was last known, greyed: never drawn at 0,0.
    if (marker) marker.getElement().dataset.fix = 'no';
    return;
  }
  if (!marker) {
    marker = new maplibregl.Marker({ element: markerElement(robot), anchor: 'left', offset: [-9, 0] });
    marker.setLngLat([robot.position.lng, robot.position.lat]).addTo(map);
    markers.set(robot.name, marker);
  }
  marker.setLngLat([robot.position.lng, robot.position.lat]);
  const node = marker.getElement();
  node.dataset.fix = 'yes';
  node.dataset.url = robot.url;
  node.dataset.estop = fmt.estop(robot);
  node.dataset.link = robot.link;
  node.dataset.lng = String(robot.position.lng);
  node.dataset.lat = String(robot.position.lat);
  node.querySelector('.fleet-marker-name').textContent = robot.title;
  node.title = `${robot.title}: ${robot.mode}, e-stop ${fmt.estop(robot)} · ${fmtLatLng(robot.position.lat, robot.position.lng)}`
    + ' · click to open its dashboard';
  node.setAttribute('aria-label', `${robot.title}: open its dashboard`);
}

// Frame every robot with a position when one more of them has one, until the operator moves the map.
function frame(robots) {
  const placed = robots.filter((r) => r.position);
  if (userMoved || placed.length <= framed) return;
  framed = placed.length;
  const bounds = new maplibregl.LngLatBounds();
  for (const r of placed) bounds.extend([r.position.lng, r.position.lat]);
  // More room on the right: each marker's name is drawn there. Less of it all on a small map.
  const side = Math.min(60, container.clientWidth / 8, container.clientHeight / 8);
  const padding = { top: side, bottom: side, left: side, right: Math.min(180, container.clientWidth / 3) };
  map.fitBounds(bounds, { padding, maxZoom: 17, duration: 0 });
}

// --- polling ---

function render(state) {
  for (const robot of state.robots) renderRow(robot);
  table.dataset.updated = String(Number(table.dataset.updated) + 1);
  if (map && map.loaded()) {
    for (const robot of state.robots) renderMarker(robot);
    frame(state.robots);
  }
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
    note.textContent = `Not updated: ${err.message}`;
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

const container = $('fleet-map');
try {
  map = createGpsMap(container, JSON.parse(container.dataset.config), { onLoad: () => render(latest) });
  for (const start of ['dragstart', 'zoomstart']) {
    map.on(start, (e) => { if (e.originalEvent) userMoved = true; });
  }
  window.roverFleetMap = map;  // for the browser tests and the curious operator's console
} catch (err) {
  const mapNote = $('fleet-map-note');
  mapNote.hidden = false;
  mapNote.textContent = `The map cannot be shown in this browser (${err.message}); the table still works.`;
}
render(latest);
timer = setTimeout(poll, POLL_MS);
