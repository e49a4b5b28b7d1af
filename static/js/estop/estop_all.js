// "Stop all" in the top bar (several robots): POST /api/estop/all, at the app's root since it is
// every robot's, retried while no answer comes back, like the page's own e-stop. The page's own
// robot is also stopped over the Drive card's socket first, when one is open. Each robot's latch
// then shows through its own pages' event streams; this only says whether the request landed.
import { ApiError, api } from '../core/api.js';
import { operatorName } from '../core/operator.js';
import { sendEstopOverSocket } from '../teleop/teleop_link.js';
import { _, formatList } from '../core/i18n.js';

const RETRY_MS = 250;
const ATTEMPTS = 40;
const NOTE_MS = 4000;
const box = document.getElementById('estop-all');
const button = document.getElementById('estop-all-engage');
const note = document.getElementById('estop-all-note');
let retryTimer = null;
let noteTimer = null;

function show(state, text) {
  box.dataset.state = state;
  button.textContent = { sending: _('STOPPING…'), done: _('ALL STOPPED'), failed: _('NOT STOPPED') }[state] || _('STOP ALL');
  clearTimeout(noteTimer);
  note.textContent = text;
  note.hidden = !text;
  // The note floats under the bar (position: absolute), so it never changes the bar's height.
  if (state === 'done') noteTimer = setTimeout(() => { note.hidden = true; show('idle', ''); }, NOTE_MS);
}

async function post(attempt) {
  try {
    const reply = await api('POST', '/api/estop/all', { by: operatorName() }, { root: true });
    const robots = Object.entries(reply.robots);
    const stopped = robots.filter(([, latch]) => latch.engaged).map(([name]) => name);
    const not = robots.filter(([, latch]) => !latch.engaged).map(([name]) => name);
    if (not.length) show('failed', _('not engaged: %(robots)s', { robots: formatList(not) }));
    else show('done', _('e-stop engaged: %(robots)s', { robots: formatList(stopped) }));
  } catch (err) {
    // Refused (signed out, ...) is final; no answer or a server error is tried again.
    const final = err instanceof ApiError && err.status < 500;
    if (!final && attempt < ATTEMPTS) {
      retryTimer = setTimeout(() => post(attempt + 1), RETRY_MS);
      return;
    }
    show('failed', _('not confirmed: %(reason)s', { reason: err.message }));
  }
}

if (box) {
  button.addEventListener('click', () => {
    clearTimeout(retryTimer);
    sendEstopOverSocket();
    show('sending', '');
    post(0);
  });
}
