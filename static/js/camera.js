// Camera panel: an MJPEG <img> of the chosen image topic (GET /stream). The stream is dropped
// while the tab is hidden, so the server can remove its subscription, and it is only requested
// for topics the ROS graph lists as images, so a missing camera is a message, not a failed request.

import { api, at } from './api.js';
import { play as playWebRtc, stop as stopWebRtc } from './camera/webrtc.js';

const card = document.getElementById('camera-card');
const STORAGE_KEY = 'rover_web.camera.topic';
const RECHECK_MS = 3000;
const IMAGE_TYPES = new Set(['sensor_msgs/msg/Image', 'sensor_msgs/msg/CompressedImage']);
const BLANK = 'data:image/gif;base64,R0lGODlhAQABAIAAAAAAAP///yH5BAEAAAAALAAAAAABAAEAAAIBRAA7';

if (card) {
  const img = document.getElementById('camera-image');
  const select = document.getElementById('camera-topic');
  const message = document.getElementById('camera-message');
  const snapshotLink = document.getElementById('camera-snapshot');
  const openLink = document.getElementById('camera-open');
  let imageTopics = new Set((card.dataset.imageTopics || '').split(' ').filter(Boolean));
  let topic = localStorage.getItem(STORAGE_KEY) || select.value || card.dataset.defaultTopic;
  let streaming = null;  // the URL being shown, or null
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
    stopWebRtc();
    if (streaming === null) return;
    streaming = null;
    img.src = BLANK;  // ends the MJPEG request; the server releases the stream
  }

  function start() {
    clearTimeout(recheckTimer);
    if (document.hidden) { stop(); return; }
    if (!imageTopics.has(topic)) {
      stop();
      say(`no image topic ${topic} in the ROS graph yet; waiting for it`);
      recheckTimer = setTimeout(refreshTopics, RECHECK_MS);
      return;
    }
    if (playWebRtc(topic, start)) {  // WebRTC first; it calls start() again if it falls back
      if (streaming !== null) { streaming = null; img.src = BLANK; }
      img.hidden = true;
      say('');
      return;
    }
    img.hidden = false;
    const url = at(`/stream?${query(topic)}&width=640`);
    if (streaming === url) return;
    streaming = url;
    say(`connecting to ${topic}…`);
    img.alt = `live image from ${topic}`;
    img.src = url;
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
    streaming = null;
    start();
  }

  img.addEventListener('load', () => { if (streaming !== null) say(''); });
  img.addEventListener('error', () => {
    if (streaming === null) return;
    streaming = null;  // the stream ended (server restarted, topic refused): look again shortly
    say(`the stream from ${topic} stopped; retrying`);
    recheckTimer = setTimeout(refreshTopics, RECHECK_MS);
  });
  select.addEventListener('change', () => choose(select.value));
  card.addEventListener('camera:transport', () => { streaming = null; start(); });
  select.addEventListener('focus', refreshTopics);
  document.addEventListener('visibilitychange', start);

  const begin = () => choose(topic);
  if (document.readyState === 'complete') begin();
  else window.addEventListener('load', begin, { once: true });
}
