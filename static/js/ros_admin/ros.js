// The /ros page: each node's parameters as a form with the right input per type, service buttons
// (std_srvs Trigger, SetBool, Empty) and forms generated from a type's fields, action goals with
// their live feedback (one EventSource per running goal) and a cancel button. Buttons this user
// may not use (a role below admin, read-only mode, a name the deny list refuses) are disabled with
// the reason as their title; the server decides all the same.
import { api, ApiError, at } from '../core/api.js';
import { _ } from '../core/i18n.js';

const layout = document.querySelector('.ros-layout');
const writeBlock = layout.dataset.writeBlock || '';
const canCancel = layout.dataset.canCancel === 'yes';

// The e-stop partial's state (body class set by estop.js); the server checks it again.
const estopEngaged = () => document.body.classList.contains('estop-engaged');

// Disabled, with why, when there is a reason; returns the button.
function allowIf(button, reason) {
  if (reason) {
    button.disabled = true;
    button.title = reason;
    button.dataset.blocked = reason;
  }
  return button;
}

const BUTTON_TYPES = new Set(['std_srvs/srv/Trigger', 'std_srvs/srv/Empty', 'std_srvs/srv/SetBool']);
const el = (tag, props = {}, ...children) => {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
};
const nodeUrl = (name) => `/api/nodes/${name.replace(/^\//, '').split('/').map(encodeURIComponent).join('/')}`;

function say(target, text, ok) {
  target.textContent = text;
  target.className = `${target.className.replace(/ ?ros-status-\w+/g, '')} ${ok ? 'ros-status-ok' : 'ros-status-error'}`;
}

// An action goal's state (ROS's GoalStatus names) in the page's language.
const GOAL_STATUS = {
  accepted: _('accepted'), executing: _('executing'), canceling: _('canceling'), succeeded: _('succeeded'),
  canceled: _('canceled'), aborted: _('aborted'), unknown: _('unknown'),
};
const goalStatus = (s) => (s ? GOAL_STATUS[s] || s : '');

function failure(err) {
  return err instanceof ApiError ? `${err.code || err.status}: ${err.message}` : _('not reached: %(reason)s', { reason: err.message });
}

// --- parameters ---

function parameterInput(p) {
  let input;
  if (p.type === 'bool') {
    input = el('input', { type: 'checkbox', checked: !!p.value });
  } else if (p.type === 'integer' || p.type === 'double') {
    input = el('input', { type: 'number', value: String(p.value), step: p.type === 'integer' ? '1' : 'any' });
    if (p.range) {
      input.min = String(p.range.from);
      input.max = String(p.range.to);
      if (p.range.step) input.step = String(p.range.step);
    }
  } else if (p.type === 'string') {
    input = el('input', { type: 'text', value: p.value });
  } else {
    input = el('input', { type: 'text', value: JSON.stringify(p.value), title: _('%(type)s, as JSON', { type: p.type }) });
  }
  input.name = p.name;
  input.disabled = p.read_only || p.hidden;
  if (p.hidden) {
    input.value = '';
    input.placeholder = _('(hidden: its name says it holds a secret)');
  }
  return input;
}

function parameterValue(p, input) {
  if (p.type === 'bool') return input.checked;
  if (p.type === 'integer' || p.type === 'double') return input.value === '' ? null : Number(input.value);
  if (p.type === 'string') return input.value;
  return JSON.parse(input.value);  // arrays: a SyntaxError is shown, nothing is sent
}

async function loadParameters(details) {
  const box = details.querySelector('.ros-params');
  box.hidden = false;
  box.textContent = _('loading…');
  let reply;
  try {
    reply = await api('GET', `${nodeUrl(details.dataset.node)}/parameters`);
  } catch (err) {
    box.textContent = failure(err);
    return;
  }
  const rows = reply.parameters.map((p) => {
    const input = parameterInput(p);
    const status = el('span', { className: 'ros-param-status small' });
    const set = allowIf(el('button', { type: 'button', textContent: _('set') }),
      (p.read_only && _('read-only: set only when the node starts')) || writeBlock || p.refused
      || (p.hidden && _('hidden value')) || (reply.safety_node && estopEngaged()
        && _('a safety node: its parameters stay as they are while the e-stop is engaged')) || '');
    set.addEventListener('click', async () => {
      let value;
      try { value = parameterValue(p, input); } catch (err) { say(status, _('not JSON: %(reason)s', { reason: err.message }), false); return; }
      try {
        await api('PUT', `${nodeUrl(details.dataset.node)}/parameters/${p.name}`, { value });
        say(status, _('set'), true);
      } catch (err) { say(status, failure(err), false); }
    });
    const label = el('td', {}, el('code', { textContent: p.name }));
    label.title = [p.type, p.description, p.read_only ? _('read-only') : ''].filter(Boolean).join(' — ');
    const tr = el('tr', {}, label, el('td', {}, input), el('td', {}, set, ' ', status));
    tr.dataset.param = p.name;
    return tr;
  });
  box.replaceChildren(el('table', {}, el('tbody', {}, ...rows)));
}

// --- forms generated from a type ---

function fieldInputs(fields, prefix) {
  return fields.map((f) => {
    const path = prefix ? `${prefix}.${f.name}` : f.name;
    if (f.kind === 'message') {
      return el('fieldset', {}, el('legend', { textContent: f.name }), ...fieldInputs(f.fields, path));
    }
    let input;
    if (f.kind === 'bool') input = el('input', { type: 'checkbox' });
    else if (f.kind === 'int') input = el('input', { type: 'number', step: '1', min: String(f.min), max: String(f.max) });
    else if (f.kind === 'float') input = el('input', { type: 'number', step: 'any' });
    else input = el('input', { type: 'text', placeholder: f.kind === 'array' ? _('%(type)s as JSON', { type: f.type }) : f.type });
    input.dataset.path = path;
    input.dataset.kind = f.kind;
    return el('label', {}, `${f.name} `, input);
  });
}

function formValue(form) {
  const out = {};
  for (const input of form.querySelectorAll('input[data-path]')) {
    const { path, kind } = input.dataset;
    let value;
    if (kind === 'bool') value = input.checked;
    else if (input.value === '') continue;  // left empty: the type's default
    else if (kind === 'int' || kind === 'float') value = Number(input.value);
    else if (kind === 'array') value = JSON.parse(input.value);
    else value = input.value;
    const parts = path.split('.');
    let at = out;
    for (const part of parts.slice(0, -1)) at = (at[part] ??= {});
    at[parts.at(-1)] = value;
  }
  return out;
}

async function typeForm(typeName, which, onSubmit, submitText) {
  const [pkg, kind, name] = typeName.split('/');
  const description = await api('GET', `/api/types/${pkg}/${kind}/${name}`);
  const form = el('form', { className: 'ros-form' }, ...fieldInputs(description[which], ''),
    el('button', { type: 'submit', textContent: submitText }));
  form.addEventListener('submit', (event) => {
    event.preventDefault();
    let value;
    try { value = formValue(form); } catch (err) { onSubmit(null, err); return; }
    onSubmit(value, null);
  });
  return form;
}

// --- services ---

const serviceResult = document.getElementById('ros-service-result');

async function callService(service, type, request) {
  try {
    const reply = await api('POST', '/api/services/call', { service, type, request });
    say(serviceResult, `${service}: ${JSON.stringify(reply.response)}`, true);
  } catch (err) {
    say(serviceResult, `${service}: ${failure(err)}`, false);
  }
}

for (const row of document.querySelectorAll('.ros-service')) {
  const { service, type } = row.dataset;
  const cell = row.querySelector('.ros-service-call');
  const reason = writeBlock || row.dataset.refused;
  if (BUTTON_TYPES.has(type)) {
    const choices = type === 'std_srvs/srv/SetBool' ? [['true', { data: true }], ['false', { data: false }]]
      : [[_('call'), {}]];
    for (const [text, request] of choices) {
      const button = allowIf(el('button', { type: 'button', textContent: text }), reason);
      button.addEventListener('click', () => callService(service, type, request));
      cell.append(button, ' ');
    }
  } else {
    const open = allowIf(el('button', { type: 'button', textContent: _('form…') }), reason);
    open.addEventListener('click', async () => {
      open.remove();
      try {
        cell.append(await typeForm(type, 'request', (request, err) => {
          if (err) say(serviceResult, _('not JSON: %(reason)s', { reason: err.message }), false);
          else callService(service, type, request);
        }, _('call')));
      } catch (err) { cell.append(failure(err)); }
    });
    cell.append(open);
  }
}

// --- actions ---

const goalsList = document.getElementById('ros-goals');

// A browser has six connections per host for all its tabs, and the e-stop needs one: at most
// MAX_LIVE goals are followed live at a time; the others get a button to follow them.
const MAX_LIVE = 2;
let live = 0;

function watchGoal(li, goal) {
  li.dataset.goal = goal.goal_id;
  if (live >= MAX_LIVE) {
    const follow = el('button', { type: 'button', textContent: _('follow') });
    follow.addEventListener('click', () => { if (live < MAX_LIVE) watchGoal(li, goal); });
    li.replaceChildren(el('code', { textContent: goal.action || goal.goal_id }), ' ', goalStatus(goal.status), ' ', follow);
    return;
  }
  live += 1;
  let ended = false;
  const end = () => { if (!ended) { ended = true; live -= 1; } };
  const status = el('span', { className: 'ros-goal-status', textContent: goalStatus(goal.status) });
  const feedback = el('pre', { className: 'ros-goal-feedback' });
  const cancel = allowIf(el('button', { type: 'button', textContent: _('cancel') }),
    canCancel ? '' : _('canceling a goal needs the operator role'));
  cancel.addEventListener('click', async () => {
    try { await api('POST', `/api/actions/${goal.goal_id}/cancel`, {}); } catch (err) { status.textContent = failure(err); }
  });
  li.replaceChildren(el('code', { textContent: goal.action || '' }), ' ', status, ' ', cancel, feedback);
  const source = new EventSource(at(`/api/actions/${goal.goal_id}/events`));
  const show = (data) => {
    if (data.action) li.querySelector('code').textContent = data.action;
    if (data.status) { status.textContent = goalStatus(data.status); li.dataset.status = data.status; }
    if (data.feedback) feedback.textContent = JSON.stringify(data.feedback);
  };
  source.addEventListener('status', (e) => show(JSON.parse(e.data)));
  source.addEventListener('feedback', (e) => show(JSON.parse(e.data)));
  source.addEventListener('result', (e) => {
    const data = JSON.parse(e.data);
    show(data);
    feedback.textContent = _('result: %(result)s', { result: JSON.stringify(data.result) });
    cancel.remove();
    source.close();
    end();
  });
  source.onerror = () => { source.close(); end(); };
}

// Finished goals are rendered by the server; only running ones are followed.
const FINAL = new Set(['succeeded', 'canceled', 'aborted', 'unknown']);
for (const li of goalsList.querySelectorAll('li[data-goal]')) {
  if (!FINAL.has(li.dataset.status)) watchGoal(li, { goal_id: li.dataset.goal, status: li.dataset.status, action: li.dataset.action });
}

for (const box of document.querySelectorAll('.ros-action')) {
  const open = allowIf(box.querySelector('.ros-goal-form'), writeBlock || box.dataset.refused);
  open.addEventListener('click', async () => {
    open.remove();
    const result = el('span', { className: 'small' });
    try {
      box.append(await typeForm(box.dataset.type, 'goal', async (goal, err) => {
        if (err) { say(result, _('not JSON: %(reason)s', { reason: err.message }), false); return; }
        try {
          const sent = await api('POST', '/api/actions/goal', { action: box.dataset.action, type: box.dataset.type, goal });
          say(result, _('accepted %(goal)s', { goal: sent.goal_id }), true);
          const li = el('li');
          goalsList.prepend(li);
          watchGoal(li, sent);
        } catch (e) { say(result, failure(e), false); }
      }, _('send goal')), result);
    } catch (err) { box.append(failure(err)); }
  });
}

for (const details of document.querySelectorAll('.ros-node')) {
  details.querySelector('.ros-load-params').addEventListener('click', () => loadParameters(details));
}
