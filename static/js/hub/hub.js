// The fleet hub's page (templates/hub.html): polls GET /api/robots once a second while shown, and
// "Stop all" posts POST /api/estop/all, then shows each robot's answer (engaged, refused, no_answer).
// Its map is the fleet page's (static/js/fleet/map.js): each robot with a position, dimmed once lost.
import { api } from '../core/api.js';
import { createFleetMap, estopState } from '../fleet/map.js';

const table = document.querySelector('#hub-table tbody');
const lastStop = document.getElementById('hub-last-stop');
const button = document.getElementById('hub-stop-all');

function cell(text) {
  const td = document.createElement('td');
  td.textContent = text;
  return td;
}

function estopText(robot) {
  const state = estopState(robot);
  return state === 'unknown' ? '—' : state;
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
  const battery = r.battery && r.battery.percent != null ? `${r.battery.percent.toFixed(0)} %` : '—';
  const position = r.position ? `${r.position.lat.toFixed(6)}, ${r.position.lng.toFixed(6)}` : '—';
  tr.append(name, cell(r.heard), cell(r.link), cell(r.mode || '—'), cell(battery), cell(estopText(r)),
            cell(position), cell((r.alerts || []).join('; ')));
  return tr;
}

function showStop(stop) {
  if (!stop) return;
  const p = document.createElement('p');
  p.textContent = `by ${stop.by}, answered in ${stop.took_s} s`;
  const ul = document.createElement('ul');
  for (const [name, a] of Object.entries(stop.robots)) {
    const li = document.createElement('li');
    li.dataset.robot = name;
    li.textContent = `${name}: ${a.result}${a.reason ? ` (${a.reason})` : ''}`;
    ul.append(li);
  }
  lastStop.replaceChildren(p, ul);
}

async function refresh() {
  if (document.hidden) return;
  try {
    const state = await api('GET', '/api/robots');
    table.replaceChildren(...state.robots.map(row));
    if (fleetMap) fleetMap.render(state.robots);
    showStop(state.last_stop);
  } catch {
    // The next second tries again; the table keeps what it last showed.
  }
}

button.addEventListener('click', async () => {
  button.disabled = true;
  try {
    showStop(await api('POST', '/api/estop/all', {}));
  } catch (err) {
    lastStop.textContent = `Stop-all failed: ${err.message}`;
  } finally {
    button.disabled = false;
  }
});

const fleetMap = createFleetMap(document.getElementById('hub-map'), document.getElementById('hub-map-note'));
if (fleetMap) {
  fleetMap.render(JSON.parse(document.getElementById('hub-state').textContent).robots);
}
setInterval(refresh, 1000);
