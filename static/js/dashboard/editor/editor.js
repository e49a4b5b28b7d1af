// Edit mode of the dashboard (templates/partials/layout_editor.html), for operators and admins.
// The live cards are hidden while editing: the editor shows one tile per card, which gridstack
// drags and resizes on a desktop, and a list with up, down and remove on a phone. Every change
// goes through the model (model.js), so Undo takes back the last one whatever made it. Save sends
// the layout to the REST API; the server checks it (a 400 names the field) and the page reloads to
// render it, with only the channels its cards need.
import { api, ApiError } from '../../core/api.js';
import { LayoutModel } from './model.js';
import { fill, read } from './settings_form.js';
import { _ } from '../../core/i18n.js';

const PHONE = window.matchMedia('(max-width: 900px)');
const CELL_PX = 56;
const $ = (id) => document.getElementById(id);
const editor = $('layout-editor');
const types = JSON.parse($('layout-card-types').textContent);
const typeOf = new Map(types.map((t) => [t.name, t]));
const { id: layoutId, layout } = JSON.parse($('layout-doc').textContent);

let model = null;
let grid = null;
let gridstackLoaded = null;
let settingsFor = null;  // the key of the card whose settings are open

function say(text, failed = false) {
  $('editor-message').textContent = text;
  $('editor-message').dataset.failed = failed ? 'yes' : 'no';
}

function loadGridstack() {
  if (window.GridStack) return Promise.resolve();
  if (!gridstackLoaded) {
    gridstackLoaded = new Promise((resolve, reject) => {
      const css = Object.assign(document.createElement('link'), { rel: 'stylesheet', href: editor.dataset.gridstackCss });
      const js = Object.assign(document.createElement('script'), { src: editor.dataset.gridstackJs });
      js.addEventListener('load', resolve);
      js.addEventListener('error', () => reject(new Error('the drag-and-drop library did not load')));
      document.head.append(css, js);
    });
  }
  return gridstackLoaded;
}

function button(text, title, onClick) {
  const b = Object.assign(document.createElement('button'), { type: 'button', textContent: text, title });
  b.addEventListener('click', onClick);
  return b;
}

function summary(card) {
  const values = Object.entries(card.settings).map(([k, v]) => (Array.isArray(v) ? v.map((s) => `${s.topic} ${s.field}`).join(', ') : `${k} ${v}`));
  return values.join(' · ');
}

function tileBody(card) {
  const t = typeOf.get(card.type);
  const body = document.createElement('div');
  body.className = 'editor-tile';
  body.dataset.card = card.type;
  const title = Object.assign(document.createElement('b'), { textContent: t ? t.title : card.type });
  const about = Object.assign(document.createElement('span'), { className: 'muted small', textContent: summary(card) || (t ? t.help : '') });
  const actions = document.createElement('span');
  actions.className = 'editor-tile-actions';
  actions.append(button(_('Settings'), _('settings of this %(type)s card', { type: card.type }), () => openSettings(card.k)),
    button(_('Remove'), _('remove this %(type)s card', { type: card.type }), () => { model.remove(card.k); render(); }));
  body.append(title, about, actions);
  return body;
}

function renderGrid() {
  grid.removeAll(true);
  for (const card of model.cards) {
    const t = typeOf.get(card.type);
    const item = document.createElement('div');
    item.className = 'grid-stack-item';
    item.dataset.k = String(card.k);
    const content = document.createElement('div');
    content.className = 'grid-stack-item-content';
    content.append(tileBody(card));
    item.append(content);
    $('editor-grid').append(item);
    grid.makeWidget(item, { x: card.x, y: card.y, w: card.w, h: card.h, minW: t ? t.min_size[0] : 1,
      minH: t ? t.min_size[1] : 1, id: String(card.k) });
  }
}

function renderList() {
  const list = $('editor-list');
  list.replaceChildren(...model.cards.map((card, i) => {
    const li = document.createElement('li');
    li.dataset.k = String(card.k);
    li.append(tileBody(card));
    const up = button(_('Up'), _('one place up'), () => { model.shift(card.k, -1); render(); });
    const down = button(_('Down'), _('one place down'), () => { model.shift(card.k, 1); render(); });
    up.disabled = i === 0;
    down.disabled = i === model.cards.length - 1;
    li.querySelector('.editor-tile-actions').prepend(up, down);
    return li;
  }));
}

function showBar() {
  $('editor-name').value = model.name;
  $('editor-undo').disabled = model.history.length === 0;
}

function render() {
  showBar();
  const phone = PHONE.matches || !grid;
  $('editor-list').hidden = !phone;
  $('editor-grid').hidden = phone;
  $('editor-help-grid').hidden = phone;
  editor.dataset.view = phone ? 'list' : 'grid';
  if (phone) renderList(); else renderGrid();
}

function gridChanged() {
  const cells = {};
  for (const node of grid.engine.nodes) cells[node.id] = { x: node.x, y: node.y, w: node.w, h: node.h };
  if (model.place(cells)) showBar();  // the grid shows it already: only Undo changes
}

async function start() {
  model = new LayoutModel(layout, types);
  if (!PHONE.matches) {
    try {
      await loadGridstack();
      grid = window.GridStack.init({ column: 12, cellHeight: CELL_PX, margin: 4, float: true, animate: false,
        resizable: { handles: 'se' } }, $('editor-grid'));
      grid.on('change', gridChanged);
    } catch (err) { say(_('%(reason)s: the list editor is shown instead', { reason: err.message }), true); }
  }
  document.body.dataset.editing = 'yes';
  editor.hidden = false;
  $('layout').hidden = true;
  render();
  say('');
}

function openSettings(k) {
  const card = model.byKey(k);
  const t = typeOf.get(card.type);
  settingsFor = k;
  $('editor-settings-title').textContent = _('%(card)s: settings', { card: t.title });
  fill($('editor-settings-fields'), t, card.settings);
  $('editor-settings').showModal();
}

$('editor-settings').addEventListener('close', () => {
  const dialog = $('editor-settings');
  if (dialog.returnValue === 'apply' && settingsFor !== null) {
    const card = model.byKey(settingsFor);
    model.setSettings(settingsFor, read($('editor-settings-fields'), typeOf.get(card.type)));
    render();
  }
  settingsFor = null;
});

async function saved(call) {
  try {
    await call();
    say(_('saved'));
    location.reload();
  } catch (err) {
    say(err instanceof ApiError ? err.message : _('the server was not reached; nothing was saved'), true);
  }
}

$('layout-edit')?.addEventListener('click', start);
$('editor-add').addEventListener('change', (e) => {
  const type = e.target.value;
  e.target.value = '';
  if (!type) return;
  if (!model.add(type)) {
    say(_('this layout has a %(card)s card already: one is the most', { card: typeOf.get(type).title }), true);
  }
  else say('');
  render();
});
$('editor-name').addEventListener('change', (e) => { model.rename(e.target.value.trim()); render(); });
$('editor-clear').addEventListener('click', () => { model.clear(); render(); });
$('editor-undo').addEventListener('click', () => { model.undo(); render(); });
$('editor-save').addEventListener('click', () => saved(() => (layoutId === null
  ? api('POST', '/api/layouts', model.toDoc()).then((r) => api('PUT', '/api/me/layout', { id: r.id }))
  : api('PUT', `/api/layouts/${layoutId}`, model.toDoc()))));
$('editor-save-new').addEventListener('click', () => saved(async () => {
  const made = await api('POST', '/api/layouts', model.toDoc());
  await api('PUT', '/api/me/layout', { id: made.id });
}));
$('editor-import').addEventListener('change', async (e) => {
  const file = e.target.files[0];
  e.target.value = '';
  if (file) saved(async () => {
    const made = await api('POST', '/api/layouts', await file.text());  // the server judges the file as it is
    await api('PUT', '/api/me/layout', { id: made.id });
  });
});
$('editor-delete').addEventListener('click', () => {
  if (layoutId === null || !window.confirm(_('Delete the layout "%(name)s" from this robot, for every user?', { name: layout.name }))) return;
  saved(() => api('DELETE', `/api/layouts/${layoutId}`));
});
$('editor-done').addEventListener('click', () => {
  if (model.history.length && !window.confirm(_('Close the editor without saving your changes?'))) return;
  location.reload();
});
PHONE.addEventListener('change', () => { if (model) render(); });
