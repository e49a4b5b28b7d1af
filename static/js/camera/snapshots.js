// Snapshot mode, for links too slow for a stream: the card shows one JPEG at a time from
// GET /snapshot, asking for the next only when the last one has arrived and a pause has passed
// (never two in flight, so the link is never filled). The page measures what it gets itself.

import { at, errorFrom } from '../core/api.js';

export const PERIOD_MS = 2000;

// Starts polling `url` into `img`; `show(figures)` gets {fps, width, height, kbps} after each image,
// `fail(message)` a reason. Returns a function that stops it.
export function pollSnapshots(img, url, show, fail) {
  let stopped = false;
  let timer = null;
  let objectUrl = null;
  const arrivals = [];  // [time ms, bytes] of the last few images
  async function next() {
    const started = performance.now();
    try {
      const response = await fetch(at(url), { cache: 'no-store' });
      if (!response.ok) throw await errorFrom(response);
      const blob = await response.blob();
      if (stopped) return;
      const previous = objectUrl;
      objectUrl = URL.createObjectURL(blob);
      img.src = objectUrl;
      if (previous) URL.revokeObjectURL(previous);
      const now = performance.now();
      arrivals.push([now, blob.size]);
      while (arrivals.length > 5) arrivals.shift();
      await img.decode().catch(() => {});
      const span = arrivals.length > 1 ? (now - arrivals[0][0]) / 1000 : (now - started) / 1000 || 1;
      const counted = arrivals.length > 1 ? arrivals.slice(1) : arrivals;
      show({
        fps: counted.length / span,
        width: img.naturalWidth,
        height: img.naturalHeight,
        kbps: counted.reduce((sum, [, bytes]) => sum + bytes, 0) * 8 / 1000 / span,
      });
    } catch (err) {
      if (!stopped) fail(err.message || String(err));
    }
    if (stopped) return;
    const took = performance.now() - started;
    timer = setTimeout(next, Math.max(PERIOD_MS - took, took));  // slower links: longer pauses
  }
  next();
  return () => {
    stopped = true;
    clearTimeout(timer);
    if (objectUrl) URL.revokeObjectURL(objectUrl);
  };
}
