// The /rosout log: the newest lines first, filtered by level (a minimum), node and text, repeats
// grouped with a count. The first page comes from GET /api/rosout (which filters and groups on the
// server); new lines arrive in batches on the `rosout` channel and are filtered and grouped here
// the same way; lines are numbered, so a missed batch is noticed and the table re-read. Pause
// stops the table moving; resume reloads it from the server.
import { api, ApiError } from '../core/api.js';
import { on } from '../live/live.js';
import { _, ngettext, formatNumber, formatTime } from '../core/i18n.js';

const LEVELS = { DEBUG: 10, INFO: 20, WARN: 30, ERROR: 40, FATAL: 50 };
const SHOWN = 200;
const $ = (id) => document.getElementById(id);
const body = $('log-body');
const level = $('log-level');
const node = $('log-node');
const contains = $('log-contains');
const pause = $('log-pause');

let rows = [];  // grouped lines, newest first, as the server sends them
let lastSeq = null;
let catchingUp = false;  // a flood makes every batch a gap: one catch-up read at a time  // the newest line number this table has taken in (null: not loaded yet)
let paused = false;
let held = 0;
let loading = 0;

function filters() {
  return { level: level.value, node: node.value.trim(), contains: contains.value.trim() };
}

function matches(line, f) {
  return line.level >= (LEVELS[f.level] ?? 0)
    && (!f.node || line.node.toLowerCase().includes(f.node.toLowerCase()))
    && (!f.contains || line.msg.toLowerCase().includes(f.contains.toLowerCase()));
}

const same = (a, b) => a.level === b.level && a.node === b.node && a.msg === b.msg;

// A log line's time to the millisecond, on a 24-hour clock, in the page's locale.
const CLOCK_MS = { hour: '2-digit', minute: '2-digit', second: '2-digit', fractionalSecondDigits: 3, hourCycle: 'h23' };

function time(stamp) {
  return formatTime(stamp * 1000, CLOCK_MS);
}

function render() {
  body.replaceChildren(...rows.slice(0, SHOWN).map((line) => {
    const tr = document.createElement('tr');
    tr.dataset.level = line.level_name;
    for (const [text, cls] of [[time(line.stamp), ''], [line.level_name, ''], [line.node, ''],
      [line.msg, 'log-msg'], [line.count > 1 ? formatNumber(line.count) : '', 'log-count']]) {
      const td = document.createElement('td');
      td.textContent = text;
      if (cls) td.className = cls;
      tr.append(td);
    }
    tr.title = line.file ? `${line.file}:${line.line} ${line.function}` : '';
    return tr;
  }));
  $('logs-count').textContent = `(${rows.length >= SHOWN ? _('newest %(num)d', { num: SHOWN }) : formatNumber(rows.length)})`;
  $('log-state').textContent = !paused ? _('live') : held
    ? ngettext('paused: %(num)d new line not shown', 'paused: %(num)d new lines not shown', held) : _('paused');
}

async function reload() {
  const f = filters();
  const query = new URLSearchParams({ limit: String(SHOWN) });
  if (f.level !== 'DEBUG') query.set('level', f.level);
  if (f.node) query.set('node', f.node);
  if (f.contains) query.set('contains', f.contains);
  const mine = ++loading;
  try {
    const reply = await api('GET', `/api/rosout?${query}`);
    if (mine !== loading || paused) return;  // a newer filter was typed meanwhile, or the table is frozen
    rows = reply.lines;
    lastSeq = reply.last_seq;
    $('log-error').hidden = true;
    render();
  } catch (err) {
    $('log-error').textContent = err instanceof ApiError ? err.message : _('the server was not reached');
    $('log-error').hidden = false;
  }
}

on('rosout', (batch) => {
  if (paused) { held += batch.lines.length; render(); return; }
  if (lastSeq === null || batch.last_seq <= lastSeq) return;  // loading, or already in the table
  // A batch this page did not get (the channel keeps only the newest), or more lines than one
  // batch holds: read the ring instead of showing a table with a hole in it.
  if (batch.first_seq > lastSeq + 1 || batch.skipped) {
    if (!catchingUp) { catchingUp = true; reload().finally(() => { catchingUp = false; }); }
    return;
  }
  const f = filters();
  for (const line of batch.lines) {  // oldest first
    if (line.seq <= lastSeq) continue;
    lastSeq = line.seq;
    if (!matches(line, f)) continue;
    if (rows.length && same(rows[0], line)) {
      rows[0] = { ...rows[0], count: rows[0].count + 1, stamp: line.stamp };
    } else {
      rows.unshift({ ...line, count: 1 });
    }
  }
  if (rows.length > SHOWN) rows.length = SHOWN;
  render();
});

let typing = 0;
for (const input of [node, contains]) {
  input.addEventListener('input', () => { clearTimeout(typing); typing = setTimeout(reload, 250); });
}
level.addEventListener('change', reload);
$('log-filters').addEventListener('submit', (e) => { e.preventDefault(); reload(); });
pause.addEventListener('click', () => {
  paused = !paused;
  pause.setAttribute('aria-pressed', String(paused));
  pause.textContent = paused ? _('Resume') : _('Pause');
  held = 0;
  if (paused) render(); else reload();
});

const initial = new URLSearchParams(location.search).get('level');
if (initial && initial.toUpperCase() in LEVELS) level.value = initial.toUpperCase();
reload();
