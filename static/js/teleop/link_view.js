// The Drive card's link line: what the server measured on this page's teleop socket (its `state`
// frames' `link`, twice a second), shown beside the stick, and a plain banner when the server
// judges the link too poor to drive. The figures and the verdict are the server's
// (rover_web/teleop/link.py): the page only shows them.

import { _, formatNumber, formatUnit, said } from '../core/i18n.js';

const ms = (v) => (v === null || v === undefined ? '—' : formatUnit(Math.round(v), 'ms'));

// The server's verdict words (rover_web/teleop/link.py), as the card says them.
const QUALITY = { ok: _('ok'), poor: _('poor'), too_poor: _('too poor') };

export function linkView(root = document) {
  const $ = (id) => root.getElementById(id);
  const box = $('teleop-linkq');
  const banner = $('teleop-link-banner');
  const set = (id, value) => { const el = $(id); if (el) el.textContent = value; };

  function show(link) {
    if (!box) return;
    box.dataset.quality = link.quality;
    set('teleop-rtt', ms(link.rtt_ms));
    set('teleop-jitter', ms(link.jitter_ms));
    set('teleop-stalls', link.stalls
      ? _('%(stalls)s (longest %(longest)s)', { stalls: formatNumber(link.stalls), longest: ms(link.last_stall_ms) })
      : formatNumber(0));
    set('teleop-quality', QUALITY[link.quality] || link.quality);
    if (banner) {
      banner.hidden = link.quality !== 'too_poor';
      banner.textContent = link.quality === 'too_poor' ? _('Link too poor to drive safely: %(why)s', { why: said(link, 'why') }) : '';
    }
  }

  // No socket, no figures: nothing on the card may look live while it is not.
  function clear() {
    if (!box) return;
    box.dataset.quality = 'unknown';
    for (const id of ['teleop-rtt', 'teleop-jitter', 'teleop-stalls', 'teleop-quality']) set(id, '—');
    if (banner) { banner.hidden = true; banner.textContent = ''; }
  }

  return { show, clear };
}
