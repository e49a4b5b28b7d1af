// The page's side of the live event stream: modules register handlers with on(channel, fn), and
// the link-health pills say how the stream is doing. The stream opens once the page's modules ran,
// and it is shared with the browser's other rover_web tabs (shared_stream.js).
// The `status` channel doubles as a heartbeat (every ROVER_WEB_STATUS_PERIOD_S): silence for three
// periods means the link is stalled even if the socket looks open, so the page says `lost` and
// replaces the stream. link/honest.js turns the state into <body data-link> and greys live values.

import { markingLive, showLink } from '../link/honest.js';
import { openStream } from './shared_stream.js';
import { _, afterPageScripts } from '../core/i18n.js';

const handlers = new Map();
const stateHandlers = new Set();
const LOST_AFTER_MS = 4000;
const REOPEN_AFTER_MS = 10000;

let stream = null;
let serverState = 'connecting';
let lastMessageAt = performance.now();  // of the last event, or of the page's start
let restartedAt = performance.now();
let troubleSince = 0;

const statusPeriodMs = () => 1000 * Number(document.body.dataset.statusPeriodS || 1);

export function on(channel, fn) {
  if (!handlers.has(channel)) handlers.set(channel, new Set());
  handlers.get(channel).add(fn);
}

export function onServerState(fn) {
  stateHandlers.add(fn);
  fn(serverState);
}

export function getServerState() { return serverState; }

function setPill(id, state, label) {
  const pill = document.getElementById(id);
  if (!pill) return;
  pill.dataset.state = state;
  pill.querySelector('b').textContent = label;
}

function setServerState(state) {
  if (state === serverState) return;
  serverState = state;
  showLink(state);
  setPill('link-server', state, SERVER_LABELS[state] || state);
  if (state !== 'live') setPill('link-robot', 'unknown', ROBOT_LABELS.unknown);
  for (const fn of stateHandlers) fn(state);
}

const SERVER_LABELS = { connecting: _('connecting'), live: _('live'), reconnecting: _('reconnecting'), lost: _('lost') };
const ROBOT_LABELS = { ok: _('ok'), degraded: _('degraded'), stale: _('stale'), no_data: _('no data'), unknown: _('unknown') };

// raw: the event's JSON text, id: its id ('' for none). Handlers get (data, {type, data, lastEventId}).
function dispatch(channel, raw, id) {
  lastMessageAt = performance.now();
  troubleSince = 0;
  setServerState('live');
  let data;
  try { data = JSON.parse(raw); } catch { return; }
  if (channel === 'status') setPill('link-robot', data.robot_link, ROBOT_LABELS[data.robot_link] || data.robot_link);
  const event = { type: channel, data: raw, lastEventId: id };
  markingLive(channel, () => {
    for (const fn of handlers.get(channel) || []) {
      try { fn(data, event); } catch (err) { console.warn(`handler for ${channel} failed`, err); }
    }
  });
}

function trouble() {
  if (!troubleSince) troubleSince = performance.now();
  if (serverState === 'live' || serverState === 'connecting') setServerState('reconnecting');
}

const ROLE_TITLES = {
  leader: _('this tab holds the stream for every rover_web tab of this browser'),
  follower: _('the stream comes from another rover_web tab of this browser'),
  own: _('this tab has a stream of its own (tabs share one only over https or on localhost)'),
};

function showRole(role) {
  const pill = document.getElementById('link-server');
  if (!pill) return;
  pill.dataset.role = role;
  pill.title = _('browser to server: the live event stream; %(role)s', { role: ROLE_TITLES[role] });
}

function open() {
  const channels = new Set((document.body.dataset.channels || 'status').split(',').filter(Boolean));
  channels.add('status');
  for (const ch of handlers.keys()) channels.add(ch);
  stream = openStream(channels, { event: dispatch, trouble, role: showRole, live: () => serverState === 'live' });
}

// Down: three heartbeats missed (a stalled link looks like an open socket), or errors for
// LOST_AFTER_MS. A silent stream (proxy, suspended laptop, radio outage) is replaced rather than
// waited on, and again every few periods while nothing comes: the old one's queued events are
// never shown, and the new one starts with the current value of each channel.
function watchdog() {
  const now = performance.now();
  const bound = 3 * statusPeriodMs();
  const silent = now - lastMessageAt > bound;
  // A stream that was live is replaced at once; one that is opening, or was replaced already,
  // gets REOPEN_AFTER_MS to answer (a slow link or a busy server is not hurried).
  const due = serverState === 'live' ? 0 : Math.max(bound, REOPEN_AFTER_MS);
  if (silent || (troubleSince && now - troubleSince > LOST_AFTER_MS)) setServerState('lost');
  if (stream && silent && now - restartedAt > due) {
    restartedAt = now;
    stream.restart();
  }
}

// Module scripts run while readyState is already 'interactive', one after another, with a
// microtask checkpoint between them: opening in a microtask would open before the page's later
// modules called on(). DOMContentLoaded fires only after every deferred/module script ran.
let opened = false;
const openOnce = () => {
  if (opened) return;
  opened = true;
  // Every module of the page has run: the "scripts have not loaded yet" notice is no longer true.
  document.getElementById('scripts-pending')?.remove();
  lastMessageAt = restartedAt = performance.now();
  open();
};
if (document.readyState === 'complete') queueMicrotask(openOnce);
else {
  afterPageScripts(openOnce);  // DOMContentLoaded, or now if it passed while a catalogue loaded
  window.addEventListener('load', openOnce);  // in case this module was loaded after DOMContentLoaded
}
setInterval(watchdog, 500);
