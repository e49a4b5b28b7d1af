// The TF page (and the replay view's frames card): the tree from the page's first snapshot, then
// from each `tf` event (one a second) on the live page; a click shows a frame's details; the
// lookup form asks the server (tf2's answer or its reason).
import { on } from '../live/live.js';
import { api } from '../core/api.js';
import { showTree } from './tree.js';
import { _, formatNumber, formatUnit } from '../core/i18n.js';

// A ROS stamp: seconds since 1970, never grouped in thousands.
const STAMP = { minimumFractionDigits: 3, maximumFractionDigits: 3, useGrouping: false };

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
    const n = (v, digits) => formatNumber(v, digits);
    out.textContent = _('translation %(x)s %(y)s %(z)s m · rotation (x y z w) %(qx)s %(qy)s %(qz)s %(qw)s · yaw %(yaw)s · at %(stamp)s', {
      x: n(x, 3), y: n(y, 3), z: n(z, 3), qx: n(qx, 4), qy: n(qy, 4), qz: n(qz, 4), qw: n(qw, 4),
      yaw: formatUnit(tf.yaw * 180 / Math.PI, '°', 1), stamp: formatUnit(tf.stamp, 's', STAMP) });
  } catch (err) {
    out.dataset.error = 'true';
    out.textContent = err.code ? `${err.code}: ${err.message}` : _('not reached: %(reason)s', { reason: err.message });
  }
});

draw(latest);
if (card.dataset.live !== 'false') on('tf', draw);
