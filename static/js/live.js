// One EventSource per page (browsers allow six HTTP/1.1 connections per host across all tabs).
// Modules register handlers with on(channel, fn); the stream opens once the page's modules ran.
// The `status` channel doubles as a heartbeat: silence means the link is stalled even if the
// socket looks open.

const handlers = new Map();
const stateHandlers = new Set();
const LOST_AFTER_MS = 4000;

let source = null;
let serverState = 'connecting';
let lastMessageAt = 0;
let troubleSince = 0;
let reopenTimer = null;

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
  setPill('link-server', state, state);
  if (state !== 'live') setPill('link-robot', 'unknown', 'unknown');
  for (const fn of stateHandlers) fn(state);
}

const ROBOT_LABELS = { ok: 'ok', degraded: 'degraded', stale: 'stale', no_data: 'no data' };

function dispatch(channel, event) {
  lastMessageAt = performance.now();
  troubleSince = 0;
  setServerState('live');
  let data;
  try { data = JSON.parse(event.data); } catch { return; }
  if (channel === 'status') setPill('link-robot', data.robot_link, ROBOT_LABELS[data.robot_link] || data.robot_link);
  for (const fn of handlers.get(channel) || []) {
    try { fn(data, event); } catch (err) { console.warn(`handler for ${channel} failed`, err); }
  }
}

function open() {
  clearTimeout(reopenTimer);
  if (source) source.close();
  const channels = new Set((document.body.dataset.channels || 'status').split(',').filter(Boolean));
  channels.add('status');
  for (const ch of handlers.keys()) channels.add(ch);
  source = new EventSource(`/api/events?channels=${[...channels].join(',')}`);
  for (const ch of channels) source.addEventListener(ch, (ev) => dispatch(ch, ev));
  source.onerror = () => {
    if (!troubleSince) troubleSince = performance.now();
    if (serverState === 'live' || serverState === 'connecting') setServerState('reconnecting');
    // A CLOSED EventSource (e.g. the server answered with an error page) never retries by itself.
    if (source.readyState === EventSource.CLOSED) reopenTimer = setTimeout(open, 1000);
  };
}

function watchdog() {
  const now = performance.now();
  if (serverState === 'live' && now - lastMessageAt > 3 * statusPeriodMs()) {
    troubleSince = now;
    setServerState('reconnecting');
    open();  // a silent stream (proxy, suspended laptop) is replaced, not waited on
  }
  if (troubleSince && now - troubleSince > LOST_AFTER_MS) setServerState('lost');
}

// Module scripts run while readyState is already 'interactive', one after another, with a
// microtask checkpoint between them: opening in a microtask would open before the page's later
// modules called on(). DOMContentLoaded fires only after every deferred/module script ran.
let opened = false;
const openOnce = () => { if (!opened) { opened = true; open(); } };
if (document.readyState === 'complete') queueMicrotask(openOnce);
else {
  document.addEventListener('DOMContentLoaded', openOnce);
  window.addEventListener('load', openOnce);  // in case this module was loaded after DOMContentLoaded
}
setInterval(watchdog, 500);
