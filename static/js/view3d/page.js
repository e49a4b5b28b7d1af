// The /3d page: one Viewer with the fixed frame, follow, top-down, layer and colour controls.
import { Viewer, webglMissing } from './viewer.js';

const $ = (id) => document.getElementById(id);
const stage = $('view3d');

if (webglMissing()) {
  stage.hidden = true;
  $('view3d-nowebgl').hidden = false;
} else {
  const viewer = new Viewer(stage, { status: $('view3d-status') });
  stage.view3d = viewer;  // for tests and the bench: project(), layers, counters
  $('view3d-fixed').addEventListener('change', (e) => viewer.setFixed(e.target.value));
  $('view3d-follow').addEventListener('change', (e) => { viewer.follow = e.target.checked; viewer.placeAll(); });
  $('view3d-top').addEventListener('click', () => viewer.topDown());
  $('view3d-color').addEventListener('change', (e) => {
    viewer.layers.cloud.colorBy = e.target.value;
    if (viewer.layers.cloud.last) viewer.layers.cloud.show(viewer.layers.cloud.last);
    viewer.requestDraw();
  });
  for (const box of document.querySelectorAll('[data-layer]')) {
    box.addEventListener('change', () => viewer.setLayer(box.dataset.layer, box.checked));
    viewer.setLayer(box.dataset.layer, box.checked && !box.disabled);
  }
  viewer.setFixed($('view3d-fixed').value);
}
