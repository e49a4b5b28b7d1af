// Mission control panels: keeps the server-rendered panels (and the dashboard summary) current
// from the `panel` and `panel_log` channels, and sends commands. The server decides what is
// allowed; the page only mirrors it so an operator sees why a button is disabled.
import { api, ApiError } from '../core/api.js';
import { on } from '../live/live.js';
import { _, said } from '../core/i18n.js';

const LIGHT_TEXT = { green: _('not running'), red: _('running'), unknown: _('unknown') };

const panelRoot = (id) => document.querySelector(`[data-panel="${CSS.escape(id)}"]`);
const summaryRoot = (id) => document.querySelector(`[data-panel-summary="${CSS.escape(id)}"]`);

function showDisplays(root, displays) {
  for (const el of root.querySelectorAll('[data-display]')) {
    const shown = displays[el.dataset.display];
    if (!shown) continue;
    el.dataset.fresh = shown.fresh ? 'yes' : 'no';
    el.querySelector('.cp-text').textContent = shown.text;
  }
}

function showLight(root, light) {
  const el = root.querySelector('.cp-light');
  if (!el) return;
  el.dataset.light = light;
  el.querySelector('.cp-light-text').textContent = LIGHT_TEXT[light] || light;
}

function inputValue(root, controlId) {
  // The value an input control would send, or undefined while the field is empty or invalid.
  const field = root.querySelector(`[data-input="${CSS.escape(controlId)}"]`);
  if (!field || field.value === '' || (field.checkValidity && !field.checkValidity())) return undefined;
  if (field.dataset.kind === 'bool') return field.value === 'true';
  if (field.dataset.kind === 'string') return field.value;
  const value = Number(field.value);
  return Number.isFinite(value) ? value : undefined;
}

function refreshButton(root, button) {
  const allowed = button.dataset.allowed === 'yes';
  const needsInput = button.dataset.needsInput === 'yes';
  button.disabled = !allowed || (needsInput && inputValue(root, button.dataset.control) === undefined);
}

function showView(root, view) {
  root.dataset.locked = view.locked ? 'yes' : 'no';
  root.querySelector('.cp-lock-state').textContent = view.locked ? _('Locked') : _('Unlocked');
  root.querySelector('[data-action="unlock"]').hidden = !view.locked;
  root.querySelector('[data-action="lock"]').hidden = view.locked;
  showLight(root, view.light);
  showDisplays(root, view.displays);
  for (const button of root.querySelectorAll('[data-control]')) {
    const control = view.controls[button.dataset.control];
    if (!control) continue;
    button.dataset.allowed = control.enabled ? 'yes' : 'no';
    button.title = said(control, 'reason');
    refreshButton(root, button);
  }
}

function showSummary(root, view) {
  showLight(root, view.light);
  showDisplays(root, view.displays);
  root.querySelector('.cp-lock-state').textContent = view.locked ? _('locked') : _('unlocked');
}

on('panel', (data) => {
  for (const [id, view] of Object.entries(data.panels)) {
    const root = panelRoot(id);
    if (root) showView(root, view);
    const summary = summaryRoot(id);
    if (summary) showSummary(summary, view);
  }
});

function addLogEntry(entry) {
  const root = entry && panelRoot(entry.panel);
  const body = root && root.querySelector('[data-log]');
  if (!body || body.querySelector(`tr[data-id="${entry.id}"]`)) return;
  const row = document.createElement('tr');
  row.dataset.id = entry.id;
  row.dataset.result = entry.result;
  const cells = [[entry.clock, 'cp-time'], [entry.label, ''], [entry.value_text, 'cp-value'],
    [entry.result, 'cp-result'], [entry.reason, 'cp-reason']];
  for (const [text, cls] of cells) {
    const cell = document.createElement('td');
    if (cls) cell.className = cls;
    cell.textContent = text;
    row.append(cell);
  }
  row.firstChild.title = entry.time;
  // Entries arrive in id order over one stream; the POST reply may beat its own event.
  const newer = [...body.children].find((r) => Number(r.dataset.id) < entry.id);
  body.insertBefore(row, newer || null);
  const keep = Number(root.dataset.logShown || 20);
  while (body.children.length > keep) body.lastElementChild.remove();
}

on('panel_log', addLogEntry);

function say(root, text, isError) {
  const el = root.querySelector('.cp-message');
  el.textContent = text;
  el.dataset.error = isError ? 'yes' : 'no';
  el.hidden = !text;
}

async function post(root, path, body) {
  const url = `/api/panels/${encodeURIComponent(root.dataset.panel)}/${path}`;
  let reply;
  try {
    reply = (await api('POST', url, body || {})) || {};
  } catch (err) {
    say(root, err instanceof ApiError ? err.message : _('The server cannot be reached: nothing was sent.'), true);
    return null;
  }
  if (reply.log) addLogEntry(reply.log);
  if (reply.state) showView(root, reply.state);
  return reply;
}

async function sendControl(root, button) {
  const id = button.dataset.control;
  const body = {};
  if (button.dataset.needsInput === 'yes') {
    const value = inputValue(root, id);
    if (value === undefined) { say(root, _('Enter a valid %(what)s first.', { what: button.dataset.label }), true); return; }
    body.value = value;
  }
  if (button.dataset.confirm === 'yes') {
    const what = body.value === undefined ? button.dataset.label : `${button.dataset.label}: ${body.value}`;
    if (!window.confirm(_('Send "%(what)s"?', { what }))) return;
    body.confirmed = true;
  }
  const reply = await post(root, id, body);
  if (reply) {
    say(root, _('%(what)s: sent %(value)s on %(topic)s', { what: button.dataset.label, value: JSON.stringify(reply.value), topic: reply.topic }), false);
  }
}

document.addEventListener('click', (event) => {
  const button = event.target.closest('button');
  const root = button && button.closest('[data-panel]');
  if (!root || button.disabled) return;
  if (button.dataset.action === 'unlock') {
    post(root, 'unlock').then((r) => r && say(root, '', false));
  } else if (button.dataset.action === 'lock') {
    post(root, 'lock').then((r) => r && say(root, '', false));
  } else if (button.dataset.control) {
    sendControl(root, button);
  }
});

document.addEventListener('input', (event) => {
  const field = event.target.closest('[data-input]');
  const root = field && field.closest('[data-panel]');
  if (!root) return;
  const button = root.querySelector(`button[data-control="${CSS.escape(field.dataset.input)}"]`);
  if (button) refreshButton(root, button);
});
