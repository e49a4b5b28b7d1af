// The fleet hub's page (templates/hub.html): polls GET /api/robots once a second while shown, and
// "Stop all" posts POST /api/estop/all, then shows each robot's answer (engaged, refused, no_answer).
// The table (table.js) sorts and filters; a row's "history" opens the robot's history (history.js);
// the map is the fleet page's (static/js/fleet/map.js): each robot with a position, dimmed once lost.
import { api } from '../core/api.js';
import { createFleetMap } from '../fleet/map.js';
import { answerText, createHistory } from './history.js';
import { createTable } from './table.js';
import { _, formatDateTime, formatUnit } from '../core/i18n.js';

const lastStop = document.getElementById('hub-last-stop');
const forgotten = document.getElementById('hub-forgotten');
const button = document.getElementById('hub-stop-all');
const table = createTable(document.getElementById('hub-table'), document.getElementById('hub-filter'),
                          document.getElementById('hub-counts'));
const history = createHistory(document.getElementById('hub-history'));

document.getElementById('hub-table').addEventListener('click', (e) => {
  const open = e.target.closest('button.hub-history-open');
  if (open) history.open(open.dataset.robot);
});

function showStop(stop) {
  if (!stop) return;
  const p = document.createElement('p');
  p.textContent = _('by %(name)s, answered in %(took)s', { name: stop.by, took: formatUnit(stop.took_s, 's') });
  const ul = document.createElement('ul');
  for (const [name, a] of Object.entries(stop.robots)) {
    const li = document.createElement('li');
    li.dataset.robot = name;
    li.textContent = `${name}: ${answerText(a)}`;
    ul.append(li);
  }
  lastStop.replaceChildren(p, ul);
}

function showForgotten(list) {
  if (!list || !list.length) return;
  forgotten.replaceChildren(...list.map((f) => {
    const li = document.createElement('li');
    li.dataset.robot = f.name;
    li.textContent = `${f.name}, ${formatDateTime(f.at * 1000)}`;
    return li;
  }));
}

async function refresh() {
  if (document.hidden) return;
  try {
    const state = await api('GET', '/api/robots');
    table.render(state.robots);
    if (fleetMap) fleetMap.render(state.robots);
    showStop(state.last_stop);
    showForgotten(state.forgotten);
  } catch {
    // The next second tries again; the table keeps what it last showed.
  }
}

button.addEventListener('click', async () => {
  button.disabled = true;
  try {
    showStop(await api('POST', '/api/estop/all', {}));
  } catch (err) {
    lastStop.textContent = _('Stop-all failed: %(reason)s', { reason: err.message });
  } finally {
    button.disabled = false;
  }
});

const initial = JSON.parse(document.getElementById('hub-state').textContent).robots;
table.render(initial);
const fleetMap = createFleetMap(document.getElementById('hub-map'), document.getElementById('hub-map-note'));
if (fleetMap) {
  fleetMap.render(initial);
}
setInterval(refresh, 1000);
