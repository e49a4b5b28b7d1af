// The TF tree drawn from one snapshot (the /api/tf shape: the live `tf` channel, or a recording's
// tree in the replay view): each frame a box under its parent as view_frames draws it, the edge
// labelled static or its rate and age, the warnings, and the picked frame's details. Pure DOM.

const fmt = (v, digits = 2, unit = '') => (v === null || v === undefined ? '–' : `${Number(v).toFixed(digits)}${unit}`);

function edgeLabel(f) {
  if (f.parent === null) return '';
  if (f.static) return 'static';
  return `${fmt(f.rate_hz, 1, ' Hz')} · ${fmt(f.age_s, 2, ' s')} old`;
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
    ['frame', name], ['parent', f.parent ?? '(root)'],
    ['kind', f.static === null ? '(only a parent)' : (f.static ? 'static' : 'dynamic')],
    ['rate', fmt(f.rate_hz, 1, ' Hz')], ['age', fmt(f.age_s, 3, ' s')],
    ['newest stamp', fmt(f.newest_stamp, 3, ' s')], ['oldest kept', fmt(f.oldest_stamp, 3, ' s')],
    ['authority', f.authority || '–'], ['received', String(f.received)],
    ['refused (unnormalised)', String(f.unnormalised)], ['children', (f.children || []).join(', ') || '–'],
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
  where.summary.textContent = names.length ? `${names.length} frames, ${tree.roots.length} root(s)` : '';
  where.warnings.replaceChildren(...tree.warnings.map((w) => {
    const li = document.createElement('li');
    li.dataset.kind = w.kind;
    li.textContent = w.message;
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
