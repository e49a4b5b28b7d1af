// A viewer's page: every control that would command the robot is disabled, with the reason. The
// server refuses such requests anyway (403); this only keeps the page honest about it. Controls
// that change nothing on the robot (a map's zoom, a topic's echo) carry data-viewer-ok.
import { _ } from '../core/i18n.js';

const REASON = document.body.dataset.readonlyReason || _('View only: commands need the operator role.');
const CONTROLS = 'main button, main input, main select, main textarea';

function disable(root) {
  for (const el of root.querySelectorAll(CONTROLS)) {
    if (el.closest('[data-viewer-ok]') || el.disabled) continue;
    el.disabled = true;
    el.title = REASON;
  }
}

if (document.body.dataset.canOperate === 'no') {
  document.body.classList.add('read-only');
  const banner = document.getElementById('readonly-banner');
  if (banner) banner.hidden = false;
  disable(document);
  // Panels and the mission editor redraw their controls from live data.
  new MutationObserver(() => disable(document)).observe(document.querySelector('main'),
    { childList: true, subtree: true });
}
