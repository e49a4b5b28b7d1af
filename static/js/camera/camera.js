// Camera panel: an MJPEG <img> of the chosen image topic (GET /stream). The stream is dropped
// while the tab is hidden, so the server can remove its subscription, and it is only requested
// for topics the ROS graph lists as images, so a missing camera is a message, not a failed request.
// Where the browser can read a response as it arrives, the page reads the MJPEG itself and
// acknowledges what it received (camera/acked_stream.js), so the server sees the link's queue even
// behind a hop that terminates TCP; otherwise the <img> plays the stream (img.dataset.transport
// says which). Under the image: the fps, size and kbit/s this viewer gets (camera/stats.js); for
// the slowest links a snapshot mode polls GET /snapshot instead (camera/snapshots.js), suggested
// when the stream's rate is very low, and remembered per browser.

import { api, at } from '../core/api.js';
import { playAcked, supported as ackedSupported } from './acked_stream.js';
import { describe, watchViewer } from './stats.js';
import { pollSnapshots } from './snapshots.js';
import { play as playWebRtc, stop as stopWebRtc } from './webrtc.js';
import { _ } from '../core/i18n.js';

const card = document.getElementById('camera-card');
const STORAGE_KEY = 'rover_web.camera.topic';
const MODE_KEY = 'rover_web.camera.mode';
// A stream this slow for this many reports in a row (2 s each) suggests snapshot mode.
const SLOW_FPS = 2;
const SLOW_REPORTS = 3;
const RECHECK_MS = 3000;
const IMAGE_TYPES = new Set(['sensor_msgs/msg/Image', 'sensor_msgs/msg/CompressedImage']);
const BLANK = 'data:image/gif;base64,R0lGODlhAQABAIAAAAAAAP///yH5BAEAAAAALAAAAAABAAEAAAIBRAA7';

if (card) {
  const img = document.getElementById('camera-image');
  const select = document.getElementById('camera-topic');
  const message = document.getElementById('camera-message');
  const snapshotLink = document.getElementById('camera-snapshot');
  const openLink = document.getElementById('camera-open');
  const modeSelect = document.getElementById('camera-mode');
  const stats = document.getElementById('camera-stats');
  const suggest = document.getElementById('camera-suggest');
  // Tags this page's stream so the server's figures for it can be found (GET /api/camera/viewers).
  const label = `card-${Date.now().toString(36)}-${Math.random().toString(36).slice(2, 8)}`;
  let mode = localStorage.getItem(MODE_KEY) === 'snapshots' ? 'snapshots' : 'live';
  let stopWatching = null;
  let slowReports = 0;
  let imageTopics = new Set((card.dataset.imageTopics || '').split(' ').filter(Boolean));
  // A layout's camera card that names a topic shows it first (rover_web/layouts); else this browser's last choice.
  let topic = card.dataset.cardTopic || localStorage.getItem(STORAGE_KEY) || select.value || card.dataset.defaultTopic;
  let streaming = null;  // the URL being shown, or null
  let stopAcked = null;  // stops the acknowledged reader, while it plays
  let recheckTimer = null;

  const query = (t) => `topic=${encodeURIComponent(t)}`;

  function say(text) {
    message.textContent = text;
    message.hidden = !text;
  }

  function ensureOption(name) {
    if ([...select.options].some((o) => o.value === name)) return;
    select.append(new Option(name, name));
  }

  function stop() {
    if (stopWatching) { stopWatching(); stopWatching = null; }
    if (stopAcked) { stopAcked(); stopAcked = null; }  // aborts its request: the server releases the stream
    stopWebRtc();
    if (streaming === null) return;
    streaming = null;
    img.src = BLANK;  // ends the MJPEG request (or the snapshot loop); the server releases the stream
  }

  // The stream ended or was refused: say so and look again shortly.
  function streamStopped() {
    if (stopWatching) { stopWatching(); stopWatching = null; }
    if (stopAcked) { stopAcked(); stopAcked = null; }
    streaming = null;
    say(_('the stream from %(topic)s stopped; retrying', { topic }));
    recheckTimer = setTimeout(refreshTopics, RECHECK_MS);
  }

  function showStats(report) {
    stats.textContent = report ? describe(report) : '';
    card.dataset.cameraFps = report ? report.fps.toFixed(2) : '';
    // Slow because of the link (the server lowered quality or size), not a camera that is slow itself.
    const slow = report && mode === 'live' && report.fps < SLOW_FPS && (!report.adapt || report.step > 0);
    slowReports = slow ? slowReports + 1 : 0;
    if (slowReports >= SLOW_REPORTS) suggest.hidden = false;
  }

  function startSnapshots() {
    const url = `/snapshot?${query(topic)}&width=640`;
    if (streaming === url) return;
    stop();
    streaming = url;
    say(_('snapshots of %(topic)s…', { topic }));
    img.alt = _('snapshots from %(topic)s', { topic });
    stopWatching = pollSnapshots(img, url, (figures) => { say(''); showStats(figures); },
      (reason) => say(_('snapshot of %(topic)s: %(reason)s', { topic, reason })));
  }

  function start() {
    clearTimeout(recheckTimer);
    if (document.hidden) { stop(); return; }
    if (!imageTopics.has(topic)) {
      stop();
      say(_('no image topic %(topic)s in the ROS graph yet; waiting for it', { topic }));
      recheckTimer = setTimeout(refreshTopics, RECHECK_MS);
      return;
    }
    if (mode === 'snapshots') { startSnapshots(); return; }  // the slowest links: no stream at all
    if (playWebRtc(topic, start)) {  // WebRTC first; it calls start() again if it falls back
      if (streaming !== null) { streaming = null; img.src = BLANK; }
      if (stopWatching) { stopWatching(); stopWatching = null; }
      if (stopAcked) { stopAcked(); stopAcked = null; }
      img.hidden = true;
      say('');
      return;
    }
    img.hidden = false;
    const url = at(`/stream?${query(topic)}&width=640&viewer=${label}`);
    if (streaming === url) return;
    stop();
    streaming = url;
    say(_('connecting to %(topic)s…', { topic }));
    img.alt = _('live image from %(topic)s', { topic });
    if (ackedSupported()) {
      img.dataset.transport = 'mjpeg-acked';
      // The page's own figures; the server's report adds whether it lowered quality or size.
      let server = null;
      stopWatching = watchViewer(label, (report) => { server = report; });
      stopAcked = playAcked(img, url, (figures) => {
        say('');
        showStats({ ...(server || { adapt: true, step: 0 }), ...figures });
      }, (reason) => {
        if (streaming !== url) return;
        streamStopped();
        say(_('the stream from %(topic)s stopped (%(reason)s); retrying', { topic, reason }));
      });
      return;
    }
    img.dataset.transport = 'mjpeg';
    img.src = url;
    stopWatching = watchViewer(label, showStats);
  }

  function setMode(value) {
    mode = value === 'snapshots' ? 'snapshots' : 'live';
    localStorage.setItem(MODE_KEY, mode);
    modeSelect.value = mode;
    suggest.hidden = true;
    slowReports = 0;
    stats.textContent = '';
    start();
  }

  async function refreshTopics() {
    try {
      const graph = await api('GET', '/api/topics');
      const images = graph.topics.filter((t) => t.types.some((type) => IMAGE_TYPES.has(type)));
      imageTopics = new Set(images.map((t) => t.name));
      for (const t of images) ensureOption(t.name);
    } catch { /* the server is away or refused; the link-health pill says so */ }
    start();
  }

  function choose(name) {
    topic = name;
    localStorage.setItem(STORAGE_KEY, name);
    ensureOption(name);
    select.value = name;
    snapshotLink.href = at(`/snapshot?${query(name)}`);
    openLink.href = at(`/stream?${query(name)}`);
    stop();
    start();
  }

  img.addEventListener('load', () => { if (streaming !== null && mode === 'live') say(''); });
  img.addEventListener('error', () => {
    if (streaming === null || mode !== 'live' || stopAcked) return;  // the acked reader says so itself
    streamStopped();  // the stream ended (server restarted, topic refused): look again shortly
  });
  select.addEventListener('change', () => choose(select.value));
  modeSelect.value = mode;
  modeSelect.addEventListener('change', () => setMode(modeSelect.value));
  suggest.querySelector('button').addEventListener('click', () => setMode('snapshots'));
  card.addEventListener('camera:transport', () => { streaming = null; start(); });
  select.addEventListener('focus', refreshTopics);
  document.addEventListener('visibilitychange', start);

  const begin = () => choose(topic);
  if (document.readyState === 'complete') begin();
  else window.addEventListener('load', begin, { once: true });
}
