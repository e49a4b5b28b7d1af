// The recordings page: operators start (all topics, a preset or a list; camera or not) and stop;
// everyone sees the running recording's status (and, once it ends, why) and the list with download
// links. The list is read from GET /api/recordings every second while the page is open: one small
// JSON a second, and no event channel to keep for a page few people have open.
import { api, at, errorFrom } from '../core/api.js';
import { _, ngettext, formatNumber, formatUnit, formatDateTime } from '../core/i18n.js';

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
  return formatUnit(bytes / (1024 * 1024), 'MB', bytes < 10 * 1024 * 1024 ? 2 : 1);
}

function duration(seconds) {
  const s = Math.round(seconds);
  return s < 60 ? formatUnit(s, 's') : `${formatUnit(Math.floor(s / 60), 'min')} ${formatUnit(s % 60, 's')}`;
}

const REASONS = {
  requested: _('stopped'), shutdown: _('stopped: the server shut down'),
  max_size: _('stopped: it reached ROVER_WEB_RECORDING_MAX_MB'),
  folder_full: _('stopped: the recordings folder is full (ROVER_WEB_RECORDINGS_MAX_MB)'),
  disk_low: _('stopped: the disk is nearly full (ROVER_WEB_RECORDINGS_MIN_FREE_MB)'),
  write_error: _('stopped: it could not be written'), subscribe_failed: _('stopped: a topic could not be subscribed to'),
  interrupted: _('interrupted: the server stopped without finishing it'),
};

function stateText(rec) {
  if (rec.state === 'recording') return _('recording');
  if (rec.source === 'uploaded') return _('uploaded by %(name)s', { name: rec.started_by });
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
  tr.append(cell(rec.name || rec.id), cell(formatDateTime(rec.started_at * 1000)),
    cell(duration(rec.duration_s), 'num'), cell(mb(rec.size), 'num'), cell(formatNumber(Object.keys(rec.topics).length), 'num'),
    cell(formatNumber(rec.messages), 'num'), cell(stateText(rec)));
  const actions = document.createElement('td');
  if (rec.state !== 'recording') {
    const link = document.createElement('a');
    link.href = at(rec.file);
    link.textContent = _('download');
    link.setAttribute('download', '');
    const replay = document.createElement('a');
    replay.href = at(`/recordings/${rec.id}/replay`);
    replay.textContent = _('replay');
    actions.append(link, ' ', replay);
    if (canDelete) {
      const remove = document.createElement('button');
      remove.type = 'button';
      remove.className = 'rec-delete';
      remove.textContent = _('delete');
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
    // Each count a call of its own: Babel's extractor misses a call nested in another's arguments.
    const messages = ngettext('%(num)d message', '%(num)d messages', running.messages);
    const topics = ngettext('%(num)d topic', '%(num)d topics', Object.keys(running.topics).length);
    statusLine.textContent = _('Recording %(name)s: %(duration)s, %(messages)s, %(size)s, %(topics)s', {
      name: running.name || running.id, duration: duration(running.duration_s), size: mb(running.size), messages, topics,
    }) + (dropped ? `, ${_('%(num)d dropped', { num: dropped })}` : '');
    return;
  }
  statusLine.dataset.state = 'idle';
  const newest = recordings[0];
  statusLine.textContent = newest && newest.id === lastEnded
    ? _('Not recording. %(name)s %(state)s.', { name: newest.name || newest.id, state: stateText(newest) }) : _('Not recording.');
}

async function refresh() {
  try {
    const { recordings } = await api('GET', '/api/recordings');
    if (running && !recordings.some((r) => r.id === running.id && r.state === 'recording')) lastEnded = running.id;
    showStatus(recordings);
    rows.replaceChildren(...(recordings.length ? recordings.map(row) : [emptyRow()]));
  } catch (err) {
    statusLine.textContent = _('The list could not be read: %(reason)s', { reason: err.message });
  }
}

function emptyRow() {
  const tr = document.createElement('tr');
  const td = cell(_('No recordings yet.'), 'muted');
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
  if (!window.confirm(_('Delete %(name)s and its file?', { name: rec.name || rec.id }))) return;
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
    said.textContent = _('Not uploaded: %(file)s is %(size)s, over ROVER_WEB_RECORDING_UPLOAD_MAX_MB (%(most)s).',
      { file: file.name, size: mb(file.size), most: mb(most) });
    return;
  }
  said.dataset.state = 'sending';
  said.textContent = _('Uploading %(file)s (%(size)s)…', { file: file.name, size: mb(file.size) });
  $('rec-upload').disabled = true;
  try {
    const response = await fetch(at(`/api/recordings/upload?${new URLSearchParams({ name })}`), {
      method: 'POST', headers: { 'Content-Type': 'application/octet-stream', Accept: 'application/json' }, body: file });
    if (!response.ok) throw await errorFrom(response);
    const made = await response.json();
    said.dataset.state = 'done';
    const messages = ngettext('%(num)d message', '%(num)d messages', made.messages);
    said.textContent = _('%(name)s uploaded: %(messages)s, %(duration)s.',
      { name: made.name || made.id, messages, duration: duration(made.duration_s) });
    $('rec-upload-form').reset();
  } catch (err) {
    said.dataset.state = 'refused';
    said.textContent = _('Not uploaded: %(reason)s', { reason: err.message });
  } finally {
    $('rec-upload').disabled = false;
  }
  refresh();
});

refresh();
setInterval(() => { if (!document.hidden) refresh(); }, POLL_MS);
