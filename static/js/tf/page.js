// The TF page (and the replay view's frames card): the tree from the page's first snapshot, then
// from each `tf` event (one a second) on the live page; a click shows a frame's details; the
// lookup form asks the server (tf2's answer or its reason).
import { on } from '../live.js';
import { api } from '../api.js';
import { showTree } from './tree.js';

const $ = (id) => document.getElementById(id);
const card = $('tf');
const where = {
  tree: $('tf-tree'), warnings: $('tf-warnings'), details: $('tf-details'), empty: $('tf-empty'),
  summary: $('tf-summary'), frameList: $('tf-frame-list'),
};
const state = { picked: null };
let latest = JSON.parse(card.dataset.tree);

function draw(tree) {
  latest = tree;
  showTree(tree, where, state);
}

where.tree.addEventListener('click', (event) => {
  const button = event.target.closest('.tf-frame');
  if (!button) return;
  state.picked = button.dataset.frame;
  draw(latest);
});

$('tf-lookup').addEventListener('submit', async (event) => {
  event.preventDefault();
  const out = $('tf-lookup-result');
  const query = new URLSearchParams({ target: $('tf-target').value.trim(), source: $('tf-source').value.trim() });
  if ($('tf-time').value) query.set('time', $('tf-time').value);
  try {
    const joiner = card.dataset.lookup.includes('?') ? '&' : '?';  // the replay's URL already holds ?t=
    const tf = await api('GET', `${card.dataset.lookup}${joiner}${query}`);
    const [x, y, z] = tf.translation;
    const [qx, qy, qz, qw] = tf.rotation;
    out.dataset.error = 'false';
    out.textContent = `translation ${x.toFixed(3)} ${y.toFixed(3)} ${z.toFixed(3)} m · rotation (x y z w) `
      + `${qx.toFixed(4)} ${qy.toFixed(4)} ${qz.toFixed(4)} ${qw.toFixed(4)} · yaw ${(tf.yaw * 180 / Math.PI).toFixed(1)}° `
      + `· at ${tf.stamp.toFixed(3)} s`;
  } catch (err) {
    out.dataset.error = 'true';
    out.textContent = err.code ? `${err.code}: ${err.message}` : `not reached: ${err.message}`;
  }
});

draw(latest);
if (card.dataset.live !== 'false') on('tf', draw);
