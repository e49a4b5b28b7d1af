// The e-stop in every page's header. Engaging is one click and is retried until the server
// confirms it; releasing is a separate button, so a double click can never release.
import { api } from './api.js';
import { on } from './live.js';
import { operatorName } from './operator.js';

const box = document.getElementById('estop');
const engageButton = document.getElementById('estop-engage');
const releaseButton = document.getElementById('estop-release');
let retryTimer = null;

function show(engaged, unconfirmed = false) {
  box.dataset.engaged = engaged ? 'yes' : 'no';
  box.dataset.unconfirmed = unconfirmed ? 'yes' : 'no';
  engageButton.setAttribute('aria-pressed', String(engaged));
  engageButton.textContent = unconfirmed ? 'E-STOP (sending…)' : engaged ? 'E-STOP ENGAGED' : 'E-STOP';
  releaseButton.hidden = !engaged;
  document.body.classList.toggle('estop-engaged', engaged);
}

const post = (engaged) => api('POST', '/api/estop', { engaged, by: operatorName() });

async function engage(attempt = 0) {
  clearTimeout(retryTimer);
  show(true, true);
  try {
    show((await post(true)).engaged);
  } catch (err) {
    console.warn('e-stop not confirmed, retrying', err);
    if (attempt < 40) retryTimer = setTimeout(() => engage(attempt + 1), 250);
    else engageButton.textContent = 'E-STOP NOT CONFIRMED';
  }
}

async function release() {
  releaseButton.disabled = true;
  try {
    show((await post(false)).engaged);
  } catch (err) {
    releaseButton.title = `release failed: ${err.message}`;
  } finally {
    releaseButton.disabled = false;
  }
}

if (box) {
  engageButton.addEventListener('click', () => engage());
  releaseButton.addEventListener('click', release);
  on('teleop', (state) => {
    if (box.dataset.unconfirmed !== 'yes') show(state.estop.engaged);
  });
}
