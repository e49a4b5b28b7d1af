// The recordings page: operators start (all topics, a preset or a list; camera or not) and stop;
// everyone sees the running recording's status (and, once it ends, why) and the list with download
// links. The list is read from GET /api/recordings every second while the page is open: one small
// JSON a second, and no event channel to keep for a page few people have open.
import { api, at, errorFrom } from '../core/api.js';

const $ = (id) => document.getElementById(id);
const form = $('rec-form');
const startButton = $('rec-start');
const stopButton = $('rec-stop');
const errorLine = $('rec-error');
const statusLine = $('rec-status');
const rows = $('rec-rows');
const canDelete = $('recording').dataset.canDelete === 'yes';
const POLL_MS = 1000;

let running = null;  // the recording in progress, as the server last said
let lastEnded = null;  // the id of the newest stopped recording, to say why it stopped

function mb(bytes) {
  return `${(bytes / (1024 * 1024)).toFixed(bytes < 10 * 1024 * 1024 ? 2 : 1)} MB`;
}

function duration(seconds) {
  const s = Math.round(seconds);
  return s < 60 ? `${s} s` : `${Math.floor(s / 60)} min ${s % 60} s`;
}

const REASONS = {
  requested: 'stopped', shutdown: 'stopped: the server shut down', max_size: 'stopped: it reached ROVER_WEB_RECORDING_MAX_MB',
  folder_full: 'stopped: the recordings folder is full (ROVER_WEB_RECORDINGS_MAX_MB)',
  disk_low: 'stopped: the disk is nearly full (ROVER_WEB_RECORDINGS_MIN_FREE_MB)',
  write_error: 'stopped: it could not be written', subscribe_failed: 'stopped: a topic could not be subscribed to',
  interrupted: 'interrupted: the server stopped without finishing it',
};

function stateText(rec) {
  if (rec.state === 'recording') return 'recording';
  if (rec.source === 'uploaded') return `uploaded by ${rec.started_by}`;
  return (REASONS[rec.stop_reason] || rec.state) + (rec.error ? ` (${rec.error})` : '');
}

function cell(text, className) {
  const td = document.createElement('td');
  td.textContent = text;
  if (className) td.className = className;
  return td;
}

function row(rec) {
  const tr = document.createElement('tr');
  tr.dataset.id = rec.id;
  tr.dataset.state = rec.state;
  tr.dataset.source = rec.source;
  tr.append(cell(rec.name || rec.id), cell(new Date(rec.started_at * 1000).toLocaleString()),
    cell(duration(rec.duration_s), 'num'), cell(mb(rec.size), 'num'), cell(String(Object.keys(rec.topics).length), 'num'),
    cell(String(rec.messages), 'num'), cell(stateText(rec)));
  const actions = document.createElement('td');
  if (rec.state !== 'recording') {
    const link = document.createElement('a');
    link.href = at(rec.file);
    link.textContent = 'download';
    link.setAttribute('download', '');
    const replay = document.createElement('a');
    replay.href = at(`/recordings/${rec.id}/replay`);
    replay.textContent = 'replay';
    actions.append(link, ' ', replay);
    if (canDelete) {
      const remove = document.createElement('button');
      remove.type = 'button';
      remove.className = 'rec-delete';
      remove.textContent = 'delete';
      remove.addEventListener('click', () => removeRecording(rec));
      actions.append(' ', remove);
    }
  }
  tr.append(actions);
  return tr;
}

function showStatus(recordings) {
  running = recordings.find((r) => r.state === 'recording') || null;
  startButton.hidden = Boolean(running);
  stopButton.hidden = !running;
  if (running) {
    const dropped = Object.values(running.dropped).reduce((a, b) => a + b, 0);
    statusLine.dataset.state = 'recording';
    statusLine.textContent = `Recording ${running.name || running.id}: ${duration(running.duration_s)}, `
      + `${running.messages} messages, ${mb(running.size)}, ${Object.keys(running.topics).length} topics`
      + (dropped ? `, ${dropped} dropped` : '');
    return;
  }
  statusLine.dataset.state = 'idle';
  const newest = recordings[0];
  statusLine.textContent = newest && newest.id === lastEnded
    ? `Not recording. ${newest.name || newest.id} ${stateText(newest)}.` : 'Not recording.';
}

async function refresh() {
  try {
    const { recordings } = await api('GET', '/api/recordings');
    if (running && !recordings.some((r) => r.id === running.id && r.state === 'recording')) lastEnded = running.id;
    showStatus(recordings);
    rows.replaceChildren(...(recordings.length ? recordings.map(row) : [emptyRow()]));
  } catch (err) {
    statusLine.textContent = `The list could not be read: ${err.message}`;
  }
}

function emptyRow() {
  const tr = document.createElement('tr');
  const td = cell('No recordings yet.', 'muted');
  td.colSpan = 8;
  tr.append(td);
  return tr;
}

function selection() {
  const choice = form.querySelector('input[name="rec-topics"]:checked').value;
  let topics = 'all';
  if (choice === 'preset') topics = `preset:${$('rec-preset').value}`;
  if (choice === 'list') topics = $('rec-list').value.split(/[\s,]+/).filter(Boolean);
  return { topics, camera: $('rec-camera').checked, name: $('rec-name').value.trim() };
}

function showError(err) {
  errorLine.hidden = !err;
  errorLine.textContent = err ? err.message : '';
}

form.addEventListener('submit', async (event) => {
  event.preventDefault();
  showError(null);
  startButton.disabled = true;
  try {
    await api('POST', '/api/recordings', selection());
  } catch (err) {
    showError(err);
  } finally {
    startButton.disabled = false;
  }
  refresh();
});

stopButton.addEventListener('click', async () => {
  if (!running) return;
  showError(null);
  stopButton.disabled = true;
  try {
    await api('POST', `/api/recordings/${running.id}/stop`, {});
    lastEnded = running.id;
  } catch (err) {
    showError(err);
  } finally {
    stopButton.disabled = false;
  }
  refresh();
});

async function removeRecording(rec) {
  if (!window.confirm(`Delete ${rec.name || rec.id} and its file?`)) return;
  showError(null);
  try {
    await api('DELETE', `/api/recordings/${rec.id}`);
  } catch (err) {
    showError(err);
  }
  refresh();
}

// Upload: the file itself is the body (the server checks it whole before keeping it).
$('rec-upload-form').addEventListener('submit', async (event) => {
  event.preventDefault();
  const file = $('rec-upload-file').files[0];
  const said = $('rec-upload-status');
  if (!file) return;
  const name = $('rec-upload-name').value.trim() || file.name.replace(/\.mcap$/i, '');
  const most = Number($('rec-upload-form').dataset.maxBytes);
  if (file.size > most) {  // said here: a server refusing a large body early may reach the page as a reset
    said.dataset.state = 'refused';
    said.textContent = `Not uploaded: ${file.name} is ${mb(file.size)}, over ROVER_WEB_RECORDING_UPLOAD_MAX_MB `
      + `(${mb(most)}).`;
    return;
  }
  said.dataset.state = 'sending';
  said.textContent = `Uploading ${file.name} (${mb(file.size)})…`;
  $('rec-upload').disabled = true;
  try {
    const response = await fetch(at(`/api/recordings/upload?${new URLSearchParams({ name })}`), {
      method: 'POST', headers: { 'Content-Type': 'application/octet-stream', Accept: 'application/json' }, body: file });
    if (!response.ok) throw await errorFrom(response);
    const made = await response.json();
    said.dataset.state = 'done';
    said.textContent = `${made.name || made.id} uploaded: ${made.messages} messages, ${duration(made.duration_s)}.`;
    $('rec-upload-form').reset();
  } catch (err) {
    said.dataset.state = 'refused';
    said.textContent = `Not uploaded: ${err.message}`;
  } finally {
    $('rec-upload').disabled = false;
  }
  refresh();
});

refresh();
setInterval(() => { if (!document.hidden) refresh(); }, POLL_MS);
