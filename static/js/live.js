// The page's side of the live event stream: modules register handlers with on(channel, fn), and
// the link-health pills say how the stream is doing. The stream opens once the page's modules ran,
// and it is shared with the browser's other rover_web tabs (shared_stream.js).
// The `status` channel doubles as a heartbeat: silence means the link is stalled even if the
// socket looks open.

import { openStream } from './shared_stream.js';

const handlers = new Map();
const stateHandlers = new Set();
const LOST_AFTER_MS = 4000;

let stream = null;
let serverState = 'connecting';
let lastMessageAt = 0;
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
  setPill('link-server', state, state);
  if (state !== 'live') setPill('link-robot', 'unknown', 'unknown');
  for (const fn of stateHandlers) fn(state);
}

const ROBOT_LABELS = { ok: 'ok', degraded: 'degraded', stale: 'stale', no_data: 'no data' };

// raw: the event's JSON text, id: its id ('' for none). Handlers get (data, {type, data, lastEventId}).
function dispatch(channel, raw, id) {
  lastMessageAt = performance.now();
  troubleSince = 0;
  setServerState('live');
  let data;
  try { data = JSON.parse(raw); } catch { return; }
  if (channel === 'status') setPill('link-robot', data.robot_link, ROBOT_LABELS[data.robot_link] || data.robot_link);
  const event = { type: channel, data: raw, lastEventId: id };
  for (const fn of handlers.get(channel) || []) {
    try { fn(data, event); } catch (err) { console.warn(`handler for ${channel} failed`, err); }
  }
}

function trouble() {
  if (!troubleSince) troubleSince = performance.now();
  if (serverState === 'live' || serverState === 'connecting') setServerState('reconnecting');
}

const ROLE_TITLES = {
  leader: 'this tab holds the stream for every rover_web tab of this browser',
  follower: 'the stream comes from another rover_web tab of this browser',
  own: 'this tab has a stream of its own (tabs share one only over https or on localhost)',
};

function showRole(role) {
  const pill = document.getElementById('link-server');
  if (!pill) return;
  pill.dataset.role = role;
  pill.title = `browser to server: the live event stream; ${ROLE_TITLES[role]}`;
}

function open() {
  const channels = new Set((document.body.dataset.channels || 'status').split(',').filter(Boolean));
  channels.add('status');
  for (const ch of handlers.keys()) channels.add(ch);
  stream = openStream(channels, { event: dispatch, trouble, role: showRole });
}

function watchdog() {
  const now = performance.now();
  if (serverState === 'live' && now - lastMessageAt > 3 * statusPeriodMs()) {
    troubleSince = now;
    setServerState('reconnecting');
    stream.restart();  // a silent stream (proxy, suspended laptop) is replaced, not waited on
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
