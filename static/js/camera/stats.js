// What the camera card's stream really gets: fps, size and kbit/s, as the server measures them for
// this page's viewer (GET /api/camera/viewers?viewer=<label>: the server adapts each MJPEG viewer to
// its link, docs/camera.md). A few hundred bytes every two seconds, and only while streaming.

import { api } from '../core/api.js';
import { _, formatNumber, formatUnit } from '../core/i18n.js';

const EVERY_MS = 2000;

// "12.5 fps · 640×480 · 850 kbit/s" (and the quality when the server lowered it).
export function describe(report) {
  const parts = [_('%(fps)s fps', { fps: formatNumber(report.fps, report.fps < 10 ? 1 : 0) })];
  if (report.width && report.height) parts.push(`${report.width}×${report.height}`);
  parts.push(formatUnit(Math.round(report.kbps), 'kbit/s'));
  if (report.adapt && report.step > 0 && report.quality) parts.push(_('quality %(quality)s', { quality: report.quality }));
  return parts.join(' · ');
}

// Polls the figures of viewer `label` and hands each report (or null: not known yet) to `show`.
export function watchViewer(label, show) {
  let timer = null;
  let stopped = false;
  async function poll() {
    try {
      const reply = await api('GET', `/api/camera/viewers?viewer=${encodeURIComponent(label)}`);
      const [report] = reply.viewers;
      if (!stopped) show(report ? { ...report, adapt: reply.adapt } : null);
    } catch { /* the server is away; the link-health pill says so */ }
    if (!stopped) timer = setTimeout(poll, EVERY_MS);
  }
  timer = setTimeout(poll, EVERY_MS / 2);
  return () => { stopped = true; clearTimeout(timer); };
}
