// The camera card over WebRTC (WHEP, POST /api/camera/whep) with the browser's own
// RTCPeerConnection: a real video codec whose bitrate follows the link, over UDP. camera.js asks
// `play(topic)` first; when WebRTC is not chosen, not offered, or does not connect within
// CONNECT_TIMEOUT_MS, it answers false and the card shows MJPEG as before. The choice (a select
// on the card) is remembered. Stats from getStats() every second: codec, fps, size, kbit/s,
// round trip and frame age (the jitter buffer's delay plus half the round trip: the browser's own
// view of how old a shown frame is). The session also carries the `teleop` data channel when
// this page may drive (camera/teleop_channel.js).

import { at } from '../core/api.js';
import { attachTeleopChannel } from './teleop_channel.js';
import { _, formatNumber, formatUnit } from '../core/i18n.js';

const STORAGE_KEY = 'rover_web.camera.transport';
const CONNECT_TIMEOUT_MS = 6000;
const GATHER_TIMEOUT_MS = 2000;
const STATS_MS = 1000;

const card = document.getElementById('camera-card');
const video = document.getElementById('camera-video');
const choice = document.getElementById('camera-transport');
const statsLine = document.getElementById('camera-webrtc-stats');

let session = null;      // { pc, location, topic, timer, statsTimer }
let failedTopic = null;  // WebRTC did not work for this topic: MJPEG until the user picks again
let onFallback = () => {};

export function wanted() {
  return Boolean(card && video && card.dataset.webrtc === 'on' && transport() === 'webrtc');
}

function transport() {
  return localStorage.getItem(STORAGE_KEY) || 'webrtc';
}

function showStats(text) {
  if (!statsLine) return;
  statsLine.textContent = text;
  statsLine.hidden = !text;
}

function gathered(pc) {
  // No trickle: the offer goes with every candidate, or what there is after GATHER_TIMEOUT_MS.
  if (pc.iceGatheringState === 'complete') return Promise.resolve();
  return new Promise((resolve) => {
    const done = () => { if (pc.iceGatheringState === 'complete') resolve(); };
    pc.addEventListener('icegatheringstatechange', done);
    setTimeout(resolve, GATHER_TIMEOUT_MS);
  });
}

// True if WebRTC is (being) shown for `topic`; false: show MJPEG. `fallback()` is called when a
// session that was tried fails later, so the card can switch.
export function play(topic, fallback) {
  onFallback = fallback || (() => {});
  if (!wanted() || failedTopic === topic) {
    stop();
    if (card) card.dataset.transportInUse = 'mjpeg';
    return false;
  }
  if (session && session.topic === topic) return true;
  stop();
  start(topic);
  return true;
}

function fail(why) {
  const topic = session ? session.topic : null;
  stop();
  failedTopic = topic;
  card.dataset.transportInUse = 'mjpeg';
  showStats(_('WebRTC unavailable (%(why)s); showing MJPEG', { why }));
  onFallback();
}

async function start(topic) {
  const pc = new RTCPeerConnection({ iceServers: [] });
  const mine = { pc, location: null, topic, timer: null, statsTimer: null, last: null };
  session = mine;
  card.dataset.transportInUse = 'connecting';
  mine.timer = setTimeout(() => { if (session === mine && pc.connectionState !== 'connected') fail(_('no connection')); },
    CONNECT_TIMEOUT_MS);
  pc.addTransceiver('video', { direction: 'recvonly' });
  if (card.dataset.canOperate === 'yes') {
    attachTeleopChannel(pc.createDataChannel('teleop', { ordered: false, maxRetransmits: 0 }));
  }
  pc.addEventListener('track', (ev) => {
    video.srcObject = ev.streams[0] || new MediaStream([ev.track]);
    video.play().catch(() => { /* autoplay of a muted video is allowed; a refusal shows the controls */ });
  });
  pc.addEventListener('connectionstatechange', () => {
    if (session !== mine) return;
    if (pc.connectionState === 'connected') {
      clearTimeout(mine.timer);
      card.dataset.transportInUse = 'webrtc';
      video.hidden = false;
      mine.statsTimer = setInterval(() => readStats(mine), STATS_MS);
    } else if (pc.connectionState === 'failed' || pc.connectionState === 'closed') {
      fail(pc.connectionState === 'failed' ? _('connection failed') : _('connection closed'));
    }
  });
  try {
    await pc.setLocalDescription(await pc.createOffer());
    await gathered(pc);
    if (session !== mine) return;
    const response = await fetch(at(`/api/camera/whep?topic=${encodeURIComponent(topic)}`), {
      method: 'POST', headers: { 'Content-Type': 'application/sdp' }, body: pc.localDescription.sdp,
      credentials: 'same-origin',
    });
    if (response.status !== 201) {
      let why = `HTTP ${response.status}`;
      try { why = (await response.json()).message || why; } catch { /* not JSON */ }
      if (session === mine) fail(why);
      return;
    }
    mine.location = response.headers.get('Location');
    const answer = await response.text();
    if (session !== mine) { release(mine); return; }
    await pc.setRemoteDescription({ type: 'answer', sdp: answer });
  } catch (err) {
    if (session === mine) fail(err && err.message ? err.message : _('error'));
  }
}

function release(s) {
  clearTimeout(s.timer);
  clearInterval(s.statsTimer);
  const close = () => { try { s.pc.close(); } catch { /* closed already */ } };
  if (!s.location) { close(); return; }
  // The DELETE first, then the close: closed first, the server would end the session itself and
  // answer the DELETE 404. keepalive: it still goes out when the page is being closed.
  const deleted = fetch(s.location, { method: 'DELETE', keepalive: true, credentials: 'same-origin' });
  s.location = null;
  deleted.catch(() => {}).finally(close);
}

export function stop() {
  if (!session) return;
  const s = session;
  session = null;
  release(s);
  attachTeleopChannel(null);
  if (video) { video.srcObject = null; video.hidden = true; }
  showStats('');
}

async function readStats(s) {
  if (session !== s) return;
  let report;
  try { report = await s.pc.getStats(); } catch { return; }
  let inbound = null; let pair = null; const codecs = new Map();
  report.forEach((r) => {
    if (r.type === 'inbound-rtp' && r.kind === 'video') inbound = r;
    else if (r.type === 'candidate-pair' && r.nominated && r.state === 'succeeded') pair = r;
    else if (r.type === 'codec') codecs.set(r.id, r);
  });
  if (!inbound) return;
  const prev = s.last;
  s.last = inbound;
  const codec = codecs.get(inbound.codecId);
  const seconds = prev ? (inbound.timestamp - prev.timestamp) / 1000 : 0;
  const kbps = prev && seconds > 0 ? (8 * (inbound.bytesReceived - prev.bytesReceived)) / seconds / 1000 : 0;
  const fps = inbound.framesPerSecond
    || (prev && seconds > 0 ? (inbound.framesDecoded - prev.framesDecoded) / seconds : 0);
  const rttMs = pair && pair.currentRoundTripTime !== undefined ? pair.currentRoundTripTime * 1000 : null;
  const jitterMs = inbound.jitterBufferEmittedCount
    ? (1000 * inbound.jitterBufferDelay) / inbound.jitterBufferEmittedCount : null;
  const ageMs = jitterMs !== null ? jitterMs + (rttMs || 0) / 2 : null;
  const stats = {
    codec: codec ? codec.mimeType.replace('video/', '') : '?',
    fps: Math.round(fps || 0),
    width: inbound.frameWidth || 0,
    height: inbound.frameHeight || 0,
    kbps: Math.round(kbps),
    rttMs: rttMs === null ? null : Math.round(rttMs),
    ageMs: ageMs === null ? null : Math.round(ageMs),
    framesDecoded: inbound.framesDecoded || 0,
  };
  card.dataset.webrtcFramesDecoded = String(stats.framesDecoded);
  const ms = (v) => (v === null ? '?' : formatUnit(v, 'ms'));
  showStats([`WebRTC ${stats.codec}`, _('%(fps)s fps', { fps: formatNumber(stats.fps) }),
    `${stats.width}×${stats.height}`, formatUnit(stats.kbps, 'kbit/s'),
    _('rtt %(rtt)s', { rtt: ms(stats.rttMs) }), _('frame age %(age)s', { age: ms(stats.ageMs) })].join(' · '));
}

if (choice) {
  choice.value = transport();
  choice.addEventListener('change', () => {
    localStorage.setItem(STORAGE_KEY, choice.value);
    failedTopic = null;  // a new choice: try again
    card.dispatchEvent(new CustomEvent('camera:transport'));
  });
}
window.addEventListener('pagehide', stop);
