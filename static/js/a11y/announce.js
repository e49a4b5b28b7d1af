// What a screen reader hears of the live state: the link pills, the e-stop and the Drive card's
// socket, each when its STATE changes (a word, not a number), through one polite live region.
// The pills themselves are not live regions: the error count and the robot's freshness change at
// the event rate, and a reader that spoke each change would be useless while driving. Changes are
// coalesced: at most one message every THROTTLE_MS, each source's latest state only, and a state
// that came back to what was last said before it was spoken is not said at all. An e-stop change
// jumps the queue (its banner is also role="alert").
import { _ } from '../core/i18n.js';

const THROTTLE_MS = 2000;

// The state words as the pills show them (static/js/live/live.js says the same words).
const WORDS = {
  connecting: _('connecting'), live: _('live'), reconnecting: _('reconnecting'), lost: _('lost'), ok: _('ok'),
  degraded: _('degraded'), stale: _('stale'), no_data: _('no data'), unknown: _('unknown'),
};
const word = (v) => WORDS[v] || v.replace('_', ' ');

// [element id, attribute, how it is said]
const SOURCES = [
  ['link-server', 'data-state', (v) => _('Server link %(state)s', { state: word(v) })],
  ['link-robot', 'data-state', (v) => _('Robot %(state)s', { state: word(v) })],
  ['link-errors', 'data-state', (v) => (v === 'errors' ? _('Errors on the robot in the last minute')
    : _('No errors on the robot'))],
  ['estop', 'data-engaged', (v) => (v === 'yes' ? _('E-stop engaged') : _('E-stop released'))],
  ['teleop-link', 'data-state', (v) => _('Drive link %(state)s', { state: word(v) })],
];

const region = document.getElementById('a11y-announcer');
const said = new Map();     // id -> the state last spoken (or first seen)
const pending = new Map();  // id -> [state, text] not spoken yet
let timer = null;
let lastSpoken = 0;

function speak() {
  timer = null;
  const lines = [];
  for (const [id, [state, text]] of pending) {
    if (said.get(id) !== state) lines.push(text);
    said.set(id, state);
  }
  pending.clear();
  if (!lines.length) return;
  lastSpoken = performance.now();
  region.textContent = `${lines.join('. ')}.`;
}

function schedule(urgent) {
  if (timer !== null && !urgent) return;
  if (timer !== null) clearTimeout(timer);
  const wait = urgent ? 0 : Math.max(0, lastSpoken + THROTTLE_MS - performance.now());
  timer = setTimeout(speak, wait);
}

function watch([id, attribute, say]) {
  const el = document.getElementById(id);
  if (!el) return;
  said.set(id, el.getAttribute(attribute));  // what the page said when it loaded is not news
  new MutationObserver(() => {
    const state = el.getAttribute(attribute);
    pending.set(id, [state, say(state || 'unknown')]);
    schedule(id === 'estop');
  }).observe(el, { attributes: true, attributeFilter: [attribute] });
}

if (region) SOURCES.forEach(watch);
