// Topic echo cards (templates/cards/echo.html): each shows the newest message of its topic from
// the topic browser's echo (GET /api/topics/echo, an event stream of its own, as the Topics page
// opens one). Like the camera's video it is closed while the tab is hidden, so the server can end
// the subscription; a layout without an echo card opens none.
import { at } from '../core/api.js';
import { _, formatUnit } from '../core/i18n.js';

const cards = [...document.querySelectorAll('[data-echo-card]')].map((el) => ({ el, source: null }));
const part = (card, cls) => card.el.querySelector(`.${cls}`);

function showError(card, text) {
  const el = part(card, 'echo-card-error');
  el.textContent = text;
  el.hidden = !text;
}

async function explain(card, url) {
  try {
    const res = await fetch(url, { headers: { Accept: 'application/json' } });
    if (!res.ok) showError(card, (await res.json()).message || _('the server answered %(status)s', { status: res.status }));
    else res.body?.cancel();
  } catch { showError(card, _('the server was not reached')); }
}

function open(card) {
  close(card);
  const url = at(`/api/topics/echo?topic=${encodeURIComponent(card.el.dataset.topic)}`);
  const source = new EventSource(url);
  card.source = source;
  const stats = (d) => {
    if (d.type) part(card, 'echo-card-type').textContent = d.type;
    if (d.stats) part(card, 'echo-card-rate').textContent = formatUnit(d.stats.rate_hz, 'Hz', 1);
  };
  source.addEventListener('stats', (ev) => { showError(card, ''); stats(JSON.parse(ev.data)); });
  source.addEventListener('echo', (ev) => {
    const d = JSON.parse(ev.data);
    stats(d);
    showError(card, d.error || '');
    if (d.msg) part(card, 'echo-card-msg').textContent = JSON.stringify(d.msg, null, 2);
  });
  source.onerror = () => {
    if (source.readyState === EventSource.CLOSED && card.source === source) explain(card, url);
  };
}

function close(card) {
  if (card.source) { card.source.close(); card.source = null; }
}

document.addEventListener('visibilitychange', () => {
  for (const card of cards) { if (document.hidden) close(card); else open(card); }
});
if (!document.hidden) cards.forEach(open);
