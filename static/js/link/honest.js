// Honest state when the event stream is not live (issue 25): the page must never show a number
// that looks live when it is not.
//
// <body data-link> says where the stream is:
//   up     events (at least the `status` heartbeat) arrive within their bound
//   stale  opening, or reconnecting after an error: what the page shows may already be old
//   down   nothing arrived for 3 heartbeat periods (a stalled or cut link), or the stream stayed
//          in error for seconds
// Every element a live event changed is marked `data-live="<channel>"`, found by watching what
// the channel's handlers change in the DOM (a MutationObserver connected only while they run),
// so no page has to list its live elements; app.css greys each marked element and tags it
// "stale" whenever data-link is not `up`. The e-stop and the link bar are not greyed (the e-stop
// must look as usable as it is): they say the connection is lost instead.

import { _ } from '../core/i18n.js';

const EXEMPT = '#estop, #estop-banner, .link-health';
const observer = new MutationObserver(() => {});
const WATCH = { subtree: true, childList: true, characterData: true, attributes: true };

function mark(record, channel) {
  if (record.type === 'attributes' && record.attributeName.startsWith('data-live')) return;
  const target = record.target;
  const el = target.nodeType === Node.ELEMENT_NODE ? target : target.parentElement;
  if (!el || el === document.body || el === document.documentElement || !el.isConnected) return;
  if (el.closest(EXEMPT) || el.hasAttribute('data-live')) return;
  el.setAttribute('data-live', channel);
}

// Runs `handlers` (one live event's handlers) and marks every element they changed as live.
export function markingLive(channel, handlers) {
  observer.observe(document.body, WATCH);
  try {
    handlers();
  } finally {
    const records = observer.takeRecords();
    observer.disconnect();
    for (const record of records) mark(record, channel);
  }
}

const LINK_OF = { live: 'up', lost: 'down' };  // connecting, reconnecting: stale

// The live.js server state ('connecting' | 'live' | 'reconnecting' | 'lost') shown on the page.
export function showLink(serverState) {
  const link = LINK_OF[serverState] || 'stale';
  document.body.dataset.link = link;
  const box = document.getElementById('estop');
  if (!box) return;
  let note = document.getElementById('estop-link');
  if (!note) {
    note = document.createElement('span');
    note.id = 'estop-link';
    note.className = 'estop-link';
    note.setAttribute('role', 'alert');
    note.textContent = _('connection lost: the state shown may be old');
    box.append(note);
  }
  note.hidden = link !== 'down';
  box.dataset.link = link;
}
