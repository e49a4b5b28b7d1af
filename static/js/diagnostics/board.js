// The diagnostics board drawn from one snapshot (the `diagnostics` channel, or a recording's board
// at a time in the replay view): the worst level per hardware id, and every status with its values.
// A stale status shows STALE. Pure DOM: no event stream, no request.

import { formatUnit } from '../core/i18n.js';

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

// d: { statuses, hardware } as the server sends them. where: { hardware, body, empty }, each an
// element or null: the card's rows, the table's body, the "nothing yet" line.
export function showBoard(d, { hardware = null, body = null, empty = null }) {
  if (hardware) {
    hardware.replaceChildren(...d.hardware.map((h) => row([h.hardware_id, h.level_name], h.level_name)));
  }
  if (body) {
    if (empty) empty.hidden = d.statuses.length > 0;
    body.replaceChildren(...d.statuses.map((s) => {
      const level = s.stale ? 'STALE' : s.level_name;
      return row([level, s.name, s.hardware_id, s.message, formatUnit(s.age_s, 's', 1), values(s.values)], level);
    }));
  }
}
