// Dashboard thumbnail of the default map: a dot where the robot is, a link to the live map.
import { on } from './live.js';

const thumb = document.getElementById('livemap-thumb');
const dot = document.getElementById('livemap-thumb-robot');
const label = document.getElementById('livemap-thumb-pose');

if (thumb && dot) {
  const width = Number(thumb.dataset.width);
  const height = Number(thumb.dataset.height);
  on('pose', (pose) => {
    const pixel = pose.pixels[thumb.dataset.map];
    const shown = pixel && pixel.inside;
    dot.hidden = !shown;
    dot.dataset.stale = pose.stale ? 'yes' : 'no';
    if (shown) {
      dot.style.left = `${(100 * pixel.x) / width}%`;
      dot.style.top = `${(100 * pixel.y) / height}%`;
    }
    label.textContent = pose.stale ? 'no pose'
      : `${pose.x.toFixed(1)}, ${pose.y.toFixed(1)} m${shown ? '' : ' (off this map)'}`;
  });
}
