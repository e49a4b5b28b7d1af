// Topic browser: the live topic list (`topics` channel) and an echo of the chosen topic
// (its own EventSource on /api/topics/echo, closed when another topic is chosen or the tab is
// hidden, so the server removes the subscription when nobody looks).
import { at, errorFrom } from '../core/api.js';
import { on } from '../live/live.js';
import { formatNumber, formatUnit } from '../core/i18n.js';

const body = document.getElementById('topics-body');
const filter = document.getElementById('topics-filter');
const count = document.getElementById('topics-count');
const panel = document.getElementById('topic-echo');
const imageTypes = new Set((panel.dataset.imageTypes || '').split(' ').filter(Boolean));
const $ = (id) => document.getElementById(id);

let topics = null;  // the latest list from the server; null until the first event
let selected = panel.dataset.selected || '';
let source = null;

function cell(text, title) {
  const td = document.createElement('td');
  td.textContent = text;
  if (title) td.title = title;
  return td;
}

function row(t) {
  const tr = document.createElement('tr');
  tr.dataset.topic = t.name;
  if (t.name === selected) tr.setAttribute('aria-selected', 'true');
  const link = document.createElement('a');
  link.href = at(`/topics?topic=${encodeURIComponent(t.name)}`);
  link.dataset.topic = t.name;
  link.textContent = t.name;
  const name = document.createElement('td');
  name.append(link);
  const type = cell(t.types.join(', '));
  type.className = 'topic-type';
  tr.append(name, type, cell(String(t.publishers), t.publisher_nodes.join(', ')),
    cell(String(t.subscribers), t.subscriber_nodes.join(', ')));
  return tr;
}

function render() {
  if (topics === null) return;
  const needle = filter.value.trim().toLowerCase();
  const shown = topics.filter((t) => !needle || t.name.toLowerCase().includes(needle)
    || t.types.some((type) => type.toLowerCase().includes(needle)));
  body.replaceChildren(...shown.map(row));
  count.textContent = `(${topics.length})`;
}

function markSelected() {
  for (const tr of body.querySelectorAll('tr')) {
    if (tr.dataset.topic === selected) tr.setAttribute('aria-selected', 'true');
    else tr.removeAttribute('aria-selected');
  }
}

function human(bytesPerS) {
  if (bytesPerS >= 1e6) return formatUnit(bytesPerS / 1e6, 'MB/s', 2);
  if (bytesPerS >= 1e3) return formatUnit(bytesPerS / 1e3, 'kB/s', 1);
  return formatUnit(bytesPerS, 'B/s', 0);
}

function showStats(d) {
  const s = d.stats;
  $('echo-type').textContent = d.type;
  $('echo-qos').textContent = d.qos;
  $('echo-rate').textContent = formatUnit(s.rate_hz, 'Hz', 2);
  $('echo-bw').textContent = human(s.bandwidth_bps);
  $('echo-size').textContent = s.size_bytes === null ? '—' : formatUnit(s.size_bytes, 'B', 0);
  $('echo-count').textContent = formatNumber(s.count);
  const isImage = imageTypes.has(d.type);
  $('echo-stream').hidden = !isImage;
  if (isImage) $('echo-stream-link').href = at(`/stream?topic=${encodeURIComponent(d.topic)}`);
}

function showError(text) {
  $('echo-error').textContent = text;
  $('echo-error').hidden = !text;
}

function closeEcho() {
  if (source) source.close();
  source = null;
}

async function explainFailure(url) {
  // EventSource hides the response; ask once more to show the server's reason. Its own fetch,
  // not api(): on success the answer is the event stream itself, which must not be read to its end.
  const abort = new AbortController();
  try {
    const res = await fetch(url, { signal: abort.signal, headers: { Accept: 'application/json' } });
    if (!res.ok) {
      showError((await errorFrom(res)).message);
      return;
    }
  } catch { /* server away */ } finally { abort.abort(); }
  setTimeout(() => { if (url === currentUrl()) openEcho(); }, 2000);
}

function currentUrl() { return at(`/api/topics/echo?topic=${encodeURIComponent(selected)}`); }

function openEcho() {
  closeEcho();
  if (!selected || document.hidden) return;
  const url = currentUrl();
  source = new EventSource(url);
  source.addEventListener('stats', (ev) => { showError(''); showStats(JSON.parse(ev.data)); });
  source.addEventListener('echo', (ev) => {
    const d = JSON.parse(ev.data);
    showStats(d);
    showError(d.error || '');
    if (d.msg) $('echo-msg').textContent = JSON.stringify(d.msg, null, 2);
  });
  const opened = source;
  source.onerror = () => {
    if (opened.readyState === EventSource.CLOSED && opened === source) explainFailure(url);
  };
}

function select(name) {
  if (name === selected && source) return;
  selected = name;
  history.replaceState(null, '', at(`/topics?topic=${encodeURIComponent(name)}`));
  markSelected();
  $('echo-empty').hidden = true;
  $('echo-body').hidden = false;
  $('echo-topic').textContent = name;
  $('echo-msg').textContent = '';
  showError('');
  for (const id of ['echo-type', 'echo-qos', 'echo-rate', 'echo-bw', 'echo-size', 'echo-count']) $(id).textContent = '—';
  openEcho();
}

on('topics', (graph) => { topics = graph.topics; render(); });
filter.addEventListener('input', render);
body.addEventListener('click', (ev) => {
  const link = ev.target.closest('a[data-topic]');
  if (!link || ev.ctrlKey || ev.metaKey || ev.shiftKey) return;
  ev.preventDefault();
  select(link.dataset.topic);
});
document.addEventListener('visibilitychange', () => { if (document.hidden) closeEcho(); else openEcho(); });
if (selected) openEcho();
