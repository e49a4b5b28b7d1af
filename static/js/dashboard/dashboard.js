import { on } from '../live/live.js';
import { _, formatNumber, formatUnit } from '../core/i18n.js';

const text = (id, value) => { const el = document.getElementById(id); if (el) el.textContent = value; };

// BatteryState's power_supply_status as rover_web/telemetry/msgs.py names it.
const SUPPLY = {
  charging: _('charging'), discharging: _('discharging'), 'not charging': _('not charging'), full: _('full'), unknown: _('unknown'),
};

on('status', (s) => {
  text('status-uptime', formatUnit(s.uptime_s, 's', 0));
  const body = document.getElementById('status-topics');
  if (!body) return;
  body.replaceChildren(...s.topics.map((t) => {
    const row = document.createElement('tr');
    row.dataset.fresh = t.fresh ? 'yes' : 'no';
    for (const value of [t.topic, t.age_s === null ? '—' : formatUnit(t.age_s, 's', 1), formatUnit(t.rate_hz, 'Hz', 1)]) {
      const cell = document.createElement('td');
      cell.textContent = value;
      row.append(cell);
    }
    return row;
  }));
});

// Only the channels of the cards on the page: live.js subscribes to every channel that has a handler,
// and a layout without the Robot card must not ask for odom and battery.
if (document.getElementById('odom-card')) {
  on('odom', (o) => {
    text('odom-linear', formatNumber(o.linear, 2));
    text('odom-angular', formatNumber(o.angular, 2));
    // The pair's separator is the language's: "1,50; 2,00" where the comma is the decimal sign.
    text('odom-position', _('%(x)s, %(y)s', { x: formatNumber(o.x, 2), y: formatNumber(o.y, 2) }));
  });

  on('battery', (b) => {
    text('odom-battery-percent', b.percent === null ? '—' : formatNumber(b.percent, 0));
    text('odom-battery-voltage', b.voltage === null ? '—' : formatNumber(b.voltage, 2));
    const el = document.getElementById('odom-battery');
    if (el) el.title = `${el.dataset.topic}: ${SUPPLY[b.status] || b.status}`;
  });
}
