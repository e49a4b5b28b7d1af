// The health bar's error pill: ERROR and FATAL lines on /rosout in the last minute (`rosout_health`).
import { on } from '../live/live.js';

on('rosout_health', (h) => {
  const pill = document.getElementById('link-errors');
  if (!pill) return;
  pill.dataset.state = h.errors_last_minute > 0 ? 'errors' : 'ok';
  pill.querySelector('b').textContent = String(h.errors_last_minute);
});
