// Diagnostics: the `diagnostics` channel drawn as the dashboard card (worst level per hardware id)
// and, on /diagnostics, the table of every status with its values. A stale status shows STALE.
import { on } from './live.js';

const $ = (id) => document.getElementById(id);

function row(cells, level) {
  const tr = document.createElement('tr');
  tr.dataset.level = level;
  for (const value of cells) {
    const td = document.createElement('td');
    if (value instanceof Node) td.append(value); else td.textContent = value;
    tr.append(td);
  }
  return tr;
}

function values(map) {
  const span = document.createDocumentFragment();
  for (const [k, v] of Object.entries(map)) {
    const kv = document.createElement('span');
    kv.className = 'diag-kv';
    kv.textContent = `${k}: ${v}`;
    span.append(kv, ' ');
  }
  return span;
}

on('diagnostics', (d) => {
  const card = $('diag-hardware');
  if (card) {
    card.replaceChildren(...d.hardware.map((h) => row([h.hardware_id, h.level_name], h.level_name)));
  }
  const table = $('diag-body');
  if (table) {
    $('diag-empty').hidden = d.statuses.length > 0;
    table.replaceChildren(...d.statuses.map((s) => {
      const level = s.stale ? 'STALE' : s.level_name;
      return row([level, s.name, s.hardware_id, s.message, `${s.age_s.toFixed(1)} s`, values(s.values)], level);
    }));
  }
});
