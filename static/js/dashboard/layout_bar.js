// The dashboard's layout bar: choosing another layout (PUT /api/me/layout, remembered on the robot
// for this user, or for every browser while sign-in is off) reloads the page, which the server
// renders from the new layout with only its cards' channels.
import { api, ApiError } from '../core/api.js';
import { _ } from '../core/i18n.js';

const select = document.getElementById('layout-select');
const message = document.getElementById('layout-message');

function say(text) { message.textContent = text; }

select?.addEventListener('change', async () => {
  const id = Number(select.value);
  if (!Number.isInteger(id) || select.value === '') return;
  select.disabled = true;
  try {
    await api('PUT', '/api/me/layout', { id });
    location.reload();
  } catch (err) {
    say(err instanceof ApiError ? err.message : _('the server was not reached'));
    select.disabled = false;
  }
});
