// A robot's history on the hub (GET /api/robots/<name>/history), newest first, a page at a time:
// found, waiting, live, lost, forgotten, e-stop engaged or released (by whom), stop-all answers.
import { api } from '../core/api.js';
import { _, formatDateTime, formatUnit } from '../core/i18n.js';

// The hub's event names (rover_web/hub) as people read them.
export const EVENT_WORDS = { found: _('found'), waiting: _('waiting'), live: _('live'), lost: _('lost'), forgotten: _('forgotten') };

// A robot's answer to a stop-all (rover_web/hub/stop_all.py): its result, and why when it refused.
const RESULT_WORDS = {
  engaged: _('engaged'), not_engaged: _('not engaged'), refused: _('refused'), no_answer: _('no answer'),
  bad_answer: _('bad answer'), error: _('error'),
};
export function answerText(a) {
  const result = RESULT_WORDS[a.result] || a.result;
  return a.reason ? _('%(result)s (%(reason)s)', { result, reason: a.reason }) : result;
}

function describe(e) {
  const d = e.detail || {};
  const when = formatDateTime(e.at * 1000);
  switch (e.event) {
    case 'estop_engaged': return `${when} · ${d.by ? _('e-stop engaged by %(name)s', { name: d.by }) : _('e-stop engaged')}`;
    case 'estop_released': return `${when} · ${d.by ? _('e-stop released by %(name)s', { name: d.by }) : _('e-stop released')}`;
    case 'stop_all': return `${when} · ${_('stop-all by %(name)s: %(result)s', { name: d.by, result: answerText(d) })}`;
    case 'forgotten': return `${when} · ${_('forgotten after %(lost)s lost', { lost: formatUnit(d.lost_for_s, 's') })}`;
    default: return `${when} · ${EVENT_WORDS[e.event] || e.event}`;
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
      li.textContent = _('The history could not be read: %(reason)s', { reason: err.message });
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
