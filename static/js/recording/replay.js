// The replay view: a recording shown on a time slider with play/pause and speed. One GET of its
// timeline (tracks, logs, audit trail, what it holds; decoded on the server) feeds the track, the
// LiveMap, the plots' topics and the lists; the diagnostics board and the camera frame at the
// slider's time are asked for as it moves (replay/*.js). Every request is a GET of the recording:
// this page sends nothing to the robot and publishes nothing.
import { api } from '../core/api.js';
import { lastIndexAtOrBefore } from './replay/at.js';
import { createCamera } from './replay/camera.js';
import { createDiagnostics } from './replay/diagnostics.js';
import { createLiveMap } from './replay/livemap.js';
import { createPlots } from './replay/plots.js';
import { createTrack } from './replay/track.js';
import { _, formatTime, formatUnit } from '../core/i18n.js';

const $ = (id) => document.getElementById(id);
const id = $('replay').dataset.id;
const settings = JSON.parse($('replay-settings').textContent);
const slider = $('replay-slider');
const playButton = $('replay-play');
const speed = $('replay-speed');
const SHOWN_LINES = 50;
const STEPS_PER_S = 10;  // the slider moves in tenths of a second (at least 1,000 steps)

let data = null;
let parts = [];
let now = 0;  // seconds since the recording's start
let playing = false;
let lastFrame = 0;

const span = () => data.end - data.start;

function clock(t) {
  return formatTime(t * 1000);
}

// The last SHOWN_LINES items at or before t, newest first (items are in time order).
function fillList(list, items, t, text) {
  const end = lastIndexAtOrBefore(items, t) + 1;
  list.replaceChildren(...items.slice(Math.max(0, end - SHOWN_LINES), end).reverse().map((item) => {
    const li = document.createElement('li');
    li.textContent = `${clock(item.t)} ${text(item)}`;
    return li;
  }));
}

function show() {
  const t = data.start + now;
  slider.value = span() > 0 ? Math.round((now / span()) * Number(slider.max)) : 0;
  $('replay-time').textContent = `${clock(t)} ${_('(+%(now)s of %(span)s)', { now: formatUnit(now, 's', 1), span: formatUnit(span(), 's', 1) })}`;
  $('replay').dataset.t = String(t);
  $('replay-tf').search = `?t=${t.toFixed(3)}`;  // the frames at the slider's time (rover_web/tf/replay.py)
  fillList($('replay-audit'), data.audit, t, (r) => `${r.by || '?'}: ${r.detail || r.action}`);
  fillList($('replay-logs'), data.logs, t, (l) => `[${l.level}] ${l.name}: ${l.msg}`);
  for (const part of parts) part.show(t);
}

function frame(stamp) {
  if (!playing) return;
  const dt = lastFrame ? (stamp - lastFrame) / 1000 : 0;
  lastFrame = stamp;
  now = Math.min(span(), now + dt * Number(speed.value));
  show();
  if (now >= span()) setPlaying(false);
  else requestAnimationFrame(frame);
}

function setPlaying(on) {
  playing = on;
  playButton.textContent = on ? _('Pause') : _('Play');
  playButton.setAttribute('aria-pressed', String(on));
  lastFrame = 0;
  if (on) requestAnimationFrame(frame);
}

playButton.addEventListener('click', () => {
  if (!data) return;
  if (!playing && now >= span()) now = 0;
  setPlaying(!playing);
});

slider.addEventListener('input', () => {
  if (!data) return;
  now = (Number(slider.value) / Number(slider.max)) * span();
  show();
});

function start() {
  slider.max = String(Math.max(1000, Math.ceil(span() * STEPS_PER_S)));
  parts = [
    createTrack(data, { name: $('replay-track-name'), map: $('replay-map'), canvas: $('replay-track'),
      position: $('replay-position') }),
    createLiveMap(data, settings, { section: $('replay-livemap'), select: $('replay-livemap-map'),
      poseSelect: $('replay-livemap-pose'), stage: $('replay-livemap-stage'), canvas: $('replay-livemap-canvas'),
      robot: $('replay-livemap-robot'), goal: $('replay-livemap-goal'), message: $('replay-livemap-message'),
      scalebar: $('replay-livemap-scalebar') }),
    createPlots(id, data, { topic: $('replay-plot-topic'), field: $('replay-plot-field'),
      fields: $('replay-plot-fields'), form: $('replay-plot-form'), list: $('replay-plot-series'),
      chart: $('replay-plot-chart'), values: $('replay-plot-values'), error: $('replay-plot-error') }),
    createDiagnostics(id, data, { table: $('replay-diag-table'), body: $('replay-diag-body'),
      empty: $('replay-diag-empty'), note: $('replay-diag-note') }),
    createCamera(id, data, settings, { select: $('replay-camera-topic'), img: $('replay-frame'),
      note: $('replay-frame-note') }),
  ];
  show();
}

async function load() {
  try {
    data = await api('GET', `/api/recordings/${id}/timeline`);
  } catch (err) {
    $('replay-error').hidden = false;
    $('replay-error').textContent = err.message;
    return;
  }
  if (data.start === null) {
    $('replay-time').textContent = _('this recording holds no message');
    return;
  }
  start();
}

load();
