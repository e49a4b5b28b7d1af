// Dashboard thumbnail of the default map: a dot where the robot is, a link to the live map.
import { on } from '../live/live.js';
import { _, formatNumber } from '../core/i18n.js';

const thumb = document.getElementById('livemap-thumb');
const dot = document.getElementById('livemap-thumb-robot');
const label = document.getElementById('livemap-thumb-pose');

if (thumb && dot) {
  const width = Number(thumb.dataset.width);
  const height = Number(thumb.dataset.height);
  // Set here, not in the template: the Content-Security-Policy allows no inline style attributes.
  const place = (x, y) => {
    dot.style.left = `${(100 * x) / width}%`;
    dot.style.top = `${(100 * y) / height}%`;
  };
  thumb.style.aspectRatio = `${width} / ${height}`;
  if (dot.dataset.x) place(Number(dot.dataset.x), Number(dot.dataset.y));
  on('pose', (pose) => {
    const pixel = pose.pixels[thumb.dataset.map];
    const shown = pixel && pixel.inside;
    dot.hidden = !shown;
    dot.dataset.stale = pose.stale ? 'yes' : 'no';
    if (shown) place(pixel.x, pixel.y);
    const at = _('%(x)s, %(y)s m', { x: formatNumber(pose.x, 1), y: formatNumber(pose.y, 1) });
    label.textContent = pose.stale ? _('no pose') : shown ? at : _('%(position)s (off this map)', { position: at });
  });
}
