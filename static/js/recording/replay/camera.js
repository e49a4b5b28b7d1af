// The replay's camera: the recorded frame at the slider's time, decoded and encoded as JPEG on the
// server (GET .../frame?topic=&t=; 204 before the topic's first frame), shown as an image.
import { at, errorFrom } from '../../core/api.js';
import { newestOnly } from './at.js';
import { _, formatTime, formatUnit } from '../../core/i18n.js';

const IMAGE_TYPES = new Set(['sensor_msgs/msg/Image', 'sensor_msgs/msg/CompressedImage']);
const MIN_GAP_MS = 80;

// els: { section, select, img, note }.
export function createCamera(recordingId, data, settings, els) {
  const topics = Object.entries(data.topics).filter(([, info]) => IMAGE_TYPES.has(info.type)).map(([t]) => t);
  if (!topics.length) {
    els.note.textContent = _('No camera in this recording (it was recorded without the camera).');
    els.img.hidden = true;
    els.select.hidden = true;
    return { show() {} };
  }
  els.select.replaceChildren(...topics.map((topic) => Object.assign(document.createElement('option'), {
    value: topic, textContent: topic, selected: topic === settings.camera_topic })));
  let shown = null;  // the object URL on screen
  let lastT = data.start;

  async function frame(key) {
    const [topic, t] = JSON.parse(key);
    const response = await fetch(at(`/api/recordings/${recordingId}/frame?${new URLSearchParams({ topic, t })}`));
    if (!response.ok) throw await errorFrom(response);
    if (response.status === 204) return { t, logged: null, blob: null };
    return { t, logged: Number(response.headers.get('X-Frame-Time')), error: response.headers.get('X-Frame-Error'),
      blob: await response.blob() };
  }

  function showFrame(answer) {
    if (shown) URL.revokeObjectURL(shown);
    shown = answer.blob ? URL.createObjectURL(answer.blob) : null;
    els.img.hidden = !shown;
    if (shown) els.img.src = shown;
    els.img.dataset.frameTime = answer.logged === null ? '' : answer.logged.toFixed(3);
    els.img.dataset.t = String(answer.t);
    els.note.textContent = answer.logged === null ? _('No frame yet at this time.')
      : _('Frame of %(time)s (%(before)s before the slider)',
        { time: formatTime(answer.logged * 1000), before: formatUnit(answer.t - answer.logged, 's', 1) })
        + (answer.error ? `: ${answer.error}` : '');
  }

  const ask = newestOnly(frame, showFrame,
    (err) => { els.note.textContent = _('The frame could not be read: %(reason)s', { reason: err.message }); }, { minGapMs: MIN_GAP_MS });
  const show = (t) => { lastT = t; ask(JSON.stringify([els.select.value, t])); };
  els.select.addEventListener('change', () => show(lastT));
  return { show };
}
