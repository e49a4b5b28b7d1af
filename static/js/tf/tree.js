// The TF tree drawn from one snapshot (the /api/tf shape: the live `tf` channel, or a recording's
// tree in the replay view): each frame a box under its parent as view_frames draws it, the edge
// labelled static or its rate and age, the warnings, and the picked frame's details. Pure DOM.

import { _, ngettext, formatNumber, formatUnit, said } from '../core/i18n.js';

// A ROS stamp: seconds since 1970, never grouped in thousands.
const STAMP = { minimumFractionDigits: 3, maximumFractionDigits: 3, useGrouping: false };
const fmt = (v, digits = 2, unit = '') => (v === null || v === undefined ? '–' : unit ? formatUnit(v, unit, digits) : formatNumber(v, digits));

function edgeLabel(f) {
  if (f.parent === null) return '';
  if (f.static) return _('static');
  return _('%(rate)s · %(age)s old', { rate: fmt(f.rate_hz, 1, 'Hz'), age: fmt(f.age_s, 2, 's') });
}

function warned(tree) {
  const names = new Set();
  for (const w of tree.warnings) {
    if (w.frame) names.add(w.frame);
    for (const f of w.frames || []) names.add(f);
  }
  return names;
}

function frameButton(name, f, state) {
  const b = document.createElement('button');
  b.type = 'button';
  b.className = 'tf-frame';
  b.textContent = name;
  b.dataset.frame = name;
  b.dataset.static = String(f.static === true);
  b.dataset.root = String(f.parent === null);
  b.dataset.warn = String(state.warned.has(name));
  b.setAttribute('aria-pressed', String(state.picked === name));
  return b;
}

function branch(name, tree, state, seen) {
  const f = tree.frames[name];
  const li = document.createElement('li');
  li.append(frameButton(name, f, state));
  const label = edgeLabel(f);
  if (label) {
    const edge = document.createElement('span');
    edge.className = 'tf-edge';
    edge.textContent = label;
    li.append(edge);
  }
  seen.add(name);
  const children = (f.children || []).filter((c) => !seen.has(c));
  if (children.length) {
    const ul = document.createElement('ul');
    for (const c of children) ul.append(branch(c, tree, state, seen));
    li.append(ul);
  }
  return li;
}

function details(name, f) {
  const dl = document.createElement('dl');
  const rows = [
    [_('frame'), name], [_('parent'), f.parent ?? _('(root)')],
    [_('kind'), f.static === null ? _('(only a parent)') : (f.static ? _('static') : _('dynamic'))],
    [_('rate'), fmt(f.rate_hz, 1, 'Hz')], [_('age'), fmt(f.age_s, 3, 's')],
    [_('newest stamp'), fmt(f.newest_stamp, STAMP, 's')], [_('oldest kept'), fmt(f.oldest_stamp, STAMP, 's')],
    [_('authority'), f.authority || '–'], [_('received'), formatNumber(f.received)],
    [_('refused (unnormalised)'), formatNumber(f.unnormalised)], [_('children'), (f.children || []).join(', ') || '–'],
  ];
  for (const [k, v] of rows) {
    const dt = document.createElement('dt');
    dt.textContent = k;
    const dd = document.createElement('dd');
    dd.textContent = v;
    dd.dataset.field = k;
    dl.append(dt, dd);
  }
  return dl;
}

// where: { tree, warnings, details, empty, summary, frameList }; state: { picked } kept by the caller.
export function showTree(tree, where, state) {
  state.warned = warned(tree);
  const names = Object.keys(tree.frames);
  where.empty.hidden = names.length > 0;
  where.summary.textContent = names.length ? `${ngettext('%(num)d frame', '%(num)d frames', names.length)}, `
    + ngettext('%(num)d root', '%(num)d roots', tree.roots.length) : '';
  where.warnings.replaceChildren(...tree.warnings.map((w) => {
    const li = document.createElement('li');
    li.dataset.kind = w.kind;
    li.textContent = said(w, 'message');
    return li;
  }));
  const seen = new Set();
  const top = document.createElement('ul');
  for (const root of tree.roots) top.append(branch(root, tree, state, seen));
  // Frames in a loop have no root above them: drawn from their smallest name, once.
  for (const name of names.sort()) if (!seen.has(name)) top.append(branch(name, tree, state, seen));
  where.tree.replaceChildren(top);
  if (where.frameList) {
    where.frameList.replaceChildren(...names.map((n) => Object.assign(document.createElement('option'), { value: n })));
  }
  if (state.picked && tree.frames[state.picked]) {
    where.details.replaceChildren(details(state.picked, tree.frames[state.picked]));
  }
}
