// The e-stop in every page's header. Engaging is one click: over the Drive card's open socket
// first, then POST /api/estop (retried) unless the server confirmed within a moment. Releasing is
// a separate button, so a double click can never release.
import { api } from './api.js';
import { on } from './live.js';
import { operatorName } from './operator.js';
import { sendEstopOverSocket } from './teleop_link.js';

const SOCKET_CONFIRM_MS = 300;
const box = document.getElementById('estop');
const engageButton = document.getElementById('estop-engage');
const releaseButton = document.getElementById('estop-release');
const note = document.getElementById('estop-note');
let retryTimer = null;
let confirmed = false;

function show(state, unconfirmed = false) {
  const engaged = state.engaged;
  box.dataset.engaged = engaged ? 'yes' : 'no';
  box.dataset.unconfirmed = unconfirmed ? 'yes' : 'no';
  engageButton.setAttribute('aria-pressed', String(engaged));
  engageButton.textContent = unconfirmed ? 'E-STOP (sending…)' : engaged ? 'E-STOP ENGAGED' : 'E-STOP';
  releaseButton.hidden = !engaged;
  document.body.classList.toggle('estop-engaged', engaged);
  if (note) {
    // The latch could not be written: it holds now, but would not survive a restart.
    note.hidden = !(engaged && state.persisted === false);
  }
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
    else engageButton.textContent = 'E-STOP NOT CONFIRMED';
  }
}

function engage() {
  clearTimeout(retryTimer);
  confirmed = false;
  show({ engaged: true }, true);
  if (sendEstopOverSocket()) {
    retryTimer = setTimeout(() => { if (!confirmed) postEngage(); }, SOCKET_CONFIRM_MS);
  } else {
    postEngage();
  }
}

async function release() {
  releaseButton.disabled = true;
  try {
    show(await post(false));
  } catch (err) {
    releaseButton.title = `release failed: ${err.message}`;
  } finally {
    releaseButton.disabled = false;
  }
}

if (box) {
  engageButton.addEventListener('click', engage);
  releaseButton.addEventListener('click', release);
  on('estop', (state) => {
    if (state.engaged) confirmed = true;
    if (box.dataset.unconfirmed !== 'yes' || state.engaged) show(state);
  });
}
