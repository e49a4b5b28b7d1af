import { on } from '../live/live.js';

const text = (id, value) => { const el = document.getElementById(id); if (el) el.textContent = value; };

on('status', (s) => {
  text('status-uptime', `${s.uptime_s.toFixed(0)} s`);
  const body = document.getElementById('status-topics');
  if (!body) return;
  body.replaceChildren(...s.topics.map((t) => {
    const row = document.createElement('tr');
    row.dataset.fresh = t.fresh ? 'yes' : 'no';
    for (const value of [t.topic, t.age_s === null ? '—' : `${t.age_s.toFixed(1)} s`, `${t.rate_hz.toFixed(1)} Hz`]) {
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
    text('odom-linear', o.linear.toFixed(2));
    text('odom-angular', o.angular.toFixed(2));
    text('odom-position', `${o.x.toFixed(2)}, ${o.y.toFixed(2)}`);
  });

  on('battery', (b) => {
    text('odom-battery-percent', b.percent === null ? '—' : b.percent.toFixed(0));
    text('odom-battery-voltage', b.voltage === null ? '—' : b.voltage.toFixed(2));
    const el = document.getElementById('odom-battery');
    if (el) el.title = `${el.dataset.topic}: ${b.status}`;
  });
}
