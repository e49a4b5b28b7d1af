// The geofence warning on every page: shown while the robot's GPS fix is outside the fence
// (the server decides; rover_web/geofence), hidden once it is back inside.
import { on } from '../live/live.js';
import { _, said } from '../core/i18n.js';

const banner = document.getElementById('geofence-banner');
const text = document.getElementById('geofence-banner-text');

on('geofence', (state) => {
  if (!banner) return;
  banner.hidden = state.state !== 'outside';
  if (state.state === 'outside') text.textContent = said(state, 'message') || _('the robot left the geofence');
  document.body.classList.toggle('geofence-breach', state.state === 'outside');
});
