// Logs cards (templates/cards/logs.html): each keeps its newest lines at or above its level from
// the `rosout` channel, numbered as the Logs page's are, and re-reads GET /api/rosout when a batch
// was missed. Every logs card of the page is served by this one module.
import { api } from '../core/api.js';
import { on } from '../live/live.js';

const LEVELS = { DEBUG: 10, INFO: 20, WARN: 30, ERROR: 40, FATAL: 50 };
const cards = [...document.querySelectorAll('[data-logs-card]')].map((el) => ({
  el,
  list: el.querySelector('.logs-card-lines'),
  min: LEVELS[el.dataset.level] ?? 0,
  limit: Number(el.dataset.lines) || 12,
  lastSeq: Number(el.dataset.lastSeq),
  reading: false,
}));

function line(l) {
  const li = document.createElement('li');
  li.dataset.level = l.level_name;
  const node = document.createElement('span');
  node.className = 'muted';
  node.textContent = l.node;
  li.append(node, ` ${l.msg}`);
  return li;
}

async function reread(card) {
  if (card.reading) return;
  card.reading = true;
  try {
    const query = new URLSearchParams({ limit: String(card.limit), level: card.el.dataset.level });
    const reply = await api('GET', `/api/rosout?${query}`);
    card.list.replaceChildren(...reply.lines.map(line));
    card.lastSeq = reply.last_seq;
  } catch { /* the next batch tries again */ } finally { card.reading = false; }
}

if (cards.length) {
  on('rosout', (batch) => {
    for (const card of cards) {
      if (batch.last_seq <= card.lastSeq) continue;
      if (batch.first_seq > card.lastSeq + 1 || batch.skipped) { reread(card); continue; }
      for (const l of batch.lines) {  // oldest first
        if (l.seq <= card.lastSeq) continue;
        card.lastSeq = l.seq;
        if (l.level < card.min) continue;
        card.list.querySelector('.logs-card-none')?.remove();
        card.list.prepend(line(l));
      }
      while (card.list.children.length > card.limit) card.list.lastElementChild.remove();
    }
  });
}
