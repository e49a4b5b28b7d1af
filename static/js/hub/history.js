// A robot's history on the hub (GET /api/robots/<name>/history), newest first, a page at a time:
// found, waiting, live, lost, forgotten, e-stop engaged or released (by whom), stop-all answers.
import { api } from '../api.js';

function describe(e) {
  const d = e.detail || {};
  const when = new Date(e.at * 1000).toLocaleString();
  switch (e.event) {
    case 'estop_engaged': return `${when} · e-stop engaged${d.by ? ` by ${d.by}` : ''}`;
    case 'estop_released': return `${when} · e-stop released${d.by ? ` by ${d.by}` : ''}`;
    case 'stop_all': return `${when} · stop-all by ${d.by}: ${d.result}${d.reason ? ` (${d.reason})` : ''}`;
    case 'forgotten': return `${when} · forgotten after ${d.lost_for_s} s lost`;
    default: return `${when} · ${e.event}`;
  }
}

export function createHistory(card) {
  const name = card.querySelector('#hub-history-name');
  const list = card.querySelector('#hub-history-list');
  const older = card.querySelector('#hub-history-older');
  let robot = null;
  let before = null;

  async function load(more) {
    const query = new URLSearchParams({ limit: '50' });
    if (more && before) query.set('before', String(before));
    try {
      const page = await api('GET', `/api/robots/${encodeURIComponent(robot)}/history?${query}`);
      const items = page.events.map((e) => {
        const li = document.createElement('li');
        li.dataset.event = e.event;
        li.textContent = describe(e);
        return li;
      });
      if (more) list.append(...items); else list.replaceChildren(...items);
      before = page.next_before;
      older.hidden = before == null;
    } catch (err) {
      const li = document.createElement('li');
      li.textContent = `The history could not be read: ${err.message}`;
      list.replaceChildren(li);
    }
  }

  card.querySelector('#hub-history-close').addEventListener('click', () => { card.hidden = true; });
  older.addEventListener('click', () => load(true));
  return {
    open(which) {
      robot = which;
      before = null;
      name.textContent = which;
      card.hidden = false;
      load(false);
    },
  };
}
