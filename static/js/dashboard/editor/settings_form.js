// A card's settings as a form, made from its type's JSON Schema (rover_web/layouts/cards.py):
// a choice for an enum, a number for an integer, text for a string, and for a plot's series one
// "topic field" per line. The server checks what comes back; this only makes it easy to write.

import { _ } from '../../core/i18n.js';

function input(name, schema, value) {
  let el;
  if (schema.enum) {
    el = document.createElement('select');
    el.append(new Option(_('(default)'), ''));
    for (const v of schema.enum) el.append(new Option(String(v), String(v)));
    el.value = value === undefined ? '' : String(value);
  } else if (schema.type === 'integer') {
    el = Object.assign(document.createElement('input'), { type: 'number', step: '1' });
    if (schema.minimum !== undefined) el.min = String(schema.minimum);
    if (schema.maximum !== undefined) el.max = String(schema.maximum);
    el.value = value === undefined ? '' : String(value);
  } else if (schema.type === 'array') {
    el = document.createElement('textarea');
    el.rows = 4;
    el.placeholder = '/odom twist.twist.linear.x';
    el.value = (value || []).map((s) => `${s.topic} ${s.field}`).join('\n');
  } else {
    el = Object.assign(document.createElement('input'), { type: 'text', autocomplete: 'off' });
    if (schema.maxLength) el.maxLength = schema.maxLength;
    el.value = value ?? '';
  }
  el.name = name;
  el.dataset.setting = name;
  return el;
}

export function fill(container, type, settings) {
  const props = type.settings.properties || {};
  container.replaceChildren();
  if (!Object.keys(props).length) {
    container.append(Object.assign(document.createElement('p'), { className: 'muted', textContent: _('This card has no settings.') }));
    return;
  }
  for (const [name, schema] of Object.entries(props)) {
    const label = document.createElement('label');
    label.className = 'editor-setting';
    const words = schema.type === 'array' ? _('%(name)s (one "topic field" per line)', { name }) : name;
    label.append(words, input(name, schema, settings[name]));
    if (schema.description) label.title = schema.description;
    container.append(label);
  }
}

// An empty field is left out: the card then uses its default (the robot's camera topic, every panel).
export function read(container, type) {
  const props = type.settings.properties || {};
  const out = {};
  for (const el of container.querySelectorAll('[data-setting]')) {
    const name = el.dataset.setting;
    const schema = props[name];
    const raw = el.value.trim();
    if (schema.type === 'array') {
      out[name] = raw.split('\n').map((l) => l.trim()).filter(Boolean).map((l) => {
        const [topic, ...rest] = l.split(/\s+/);
        return { topic, field: rest.join(' ') };
      });
    } else if (raw === '') {
      continue;
    } else if (schema.type === 'integer' || (schema.enum && typeof schema.enum[0] === 'number')) {
      out[name] = Number(raw);
    } else {
      out[name] = raw;
    }
  }
  return out;
}
