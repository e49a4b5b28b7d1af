// The 3D view's dashboard card: the same Viewer as /3d, in the fixed frame of the card's settings.
import { Viewer, webglMissing } from './viewer.js';

for (const card of document.querySelectorAll('[data-view3d-card]')) {
  const stage = card.querySelector('[data-view3d-stage]');
  if (webglMissing()) {
    stage.hidden = true;
    card.querySelector('[data-view3d-nowebgl]').hidden = false;
    continue;
  }
  const viewer = new Viewer(stage, { status: card.querySelector('[data-view3d-status]') });
  stage.view3d = viewer;
  viewer.setFixed(card.dataset.fixed || 'robot');
  viewer.follow = true;
  viewer.setLayer('tf', false);
  viewer.setLayer('cloud', true);
}
