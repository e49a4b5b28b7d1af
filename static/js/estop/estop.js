// The e-stop in every page's header. Engaging is one click: over the Drive card's open socket
// first, then POST /api/estop (retried) unless the server confirmed within a moment. Releasing is
// a separate button in the banner an engaged latch shows under the bar, and it asks first in a
// dialog of the page (<dialog>: focus stays in it, Escape keeps the robot stopped), so neither a
// double click nor a stray tap can release.
import { api } from '../core/api.js';
import { on } from '../live/live.js';
import { operatorName } from '../core/operator.js';
import { sendEstopOverSocket } from '../teleop/teleop_link.js';
import { _, formatTime } from '../core/i18n.js';

const SOCKET_CONFIRM_MS = 300;
const box = document.getElementById('estop');
const engageButton = document.getElementById('estop-engage');
const stateWord = engageButton?.querySelector('.estop-state');
const banner = document.getElementById('estop-banner');
const since = document.getElementById('estop-banner-since');
const releaseButton = document.getElementById('estop-release');
const dialog = document.getElementById('estop-release-dialog');
const dialogError = document.getElementById('estop-release-error');
const note = document.getElementById('estop-note');
let retryTimer = null;
let confirmed = false;

function sinceText(state) {
  if (!state.since) return state.by ? _('By %(name)s.', { name: state.by }) : '';
  const at = formatTime(state.since * 1000);
  return state.by ? _('By %(name)s at %(time)s.', { name: state.by, time: at }) : _('At %(time)s.', { time: at });
}

function show(state, unconfirmed = false) {
  const engaged = state.engaged;
  box.dataset.engaged = engaged ? 'yes' : 'no';
  box.dataset.unconfirmed = unconfirmed ? 'yes' : 'no';
  engageButton.setAttribute('aria-pressed', String(engaged));
  stateWord.textContent = unconfirmed ? ` ${_('(sending…)')}` : engaged ? ` ${_('ENGAGED')}` : '';
  banner.hidden = !engaged;
  if (engaged && !unconfirmed) since.textContent = sinceText(state);
  document.body.classList.toggle('estop-engaged', engaged);
  if (!engaged && dialog.open) dialog.close('cancel');  // released elsewhere: nothing left to ask
  // The latch could not be written: it holds now, but would not survive a restart.
  note.hidden = !(engaged && state.persisted === false);
}

const post = (engaged) => api('POST', '/api/estop', { engaged, by: operatorName() });

async function postEngage(attempt = 0) {
  try {
    const state = await post(true);
    confirmed = true;
    show(state);
  } catch (err) {
    console.warn('e-stop not confirmed, retrying', err);
    if (attempt < 40) retryTimer = setTimeout(() => postEngage(attempt + 1), 250);
    else stateWord.textContent = ` ${_('NOT CONFIRMED')}`;
  }
}

function engage() {
  clearTimeout(retryTimer);
  confirmed = false;
  if (dialog.open) dialog.close('cancel');
  show({ engaged: true }, true);
  if (sendEstopOverSocket()) {
    retryTimer = setTimeout(() => { if (!confirmed) postEngage(); }, SOCKET_CONFIRM_MS);
  } else {
    postEngage();
  }
}

// Escape closes a dialog without touching its returnValue: it is cleared on every opening, or an
// Escape after a refused release would release again.
function openDialog(fresh) {
  if (fresh) dialogError.hidden = true;
  dialog.returnValue = '';
  if (!dialog.open) dialog.showModal();
}

async function release() {
  releaseButton.disabled = true;
  try {
    show(await post(false));
  } catch (err) {
    // Refused (another engage came first, the disk, the role): the latch holds; say why.
    dialogError.textContent = _('Not released: %(reason)s', { reason: err.message });
    dialogError.hidden = false;
    releaseButton.title = _('release failed: %(reason)s', { reason: err.message });
    openDialog(false);
  } finally {
    releaseButton.disabled = false;
  }
}

if (box) {
  engageButton.addEventListener('click', engage);
  // The Drive card's own E-STOP under the thumb (partials/teleop.html), the same engage.
  for (const other of document.querySelectorAll('[data-estop-engage]')) other.addEventListener('click', engage);
  // The e-stop is a form so that it works before this module runs (partials/estop.html); from now
  // on the click above engages, over the open socket first, and the form is not sent too.
  box.addEventListener('submit', (event) => event.preventDefault());
  releaseButton.addEventListener('click', () => openDialog(true));
  // <form method="dialog">: the button pressed is the dialog's returnValue; Escape closes with ''.
  dialog.addEventListener('close', () => { if (dialog.returnValue === 'release') release(); });
  on('estop', (state) => {
    if (state.engaged) confirmed = true;
    if (box.dataset.unconfirmed !== 'yes' || state.engaged) show(state);
  });
}
