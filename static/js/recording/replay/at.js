// Small helpers the replay view's parts share: finding a series' value at a time, and asking the
// server about the newest time only.

// The index of the last point with p.t <= t in points sorted by t, or -1 (binary search: a
// thinned track has up to 5,000 points and the slider moves at the display's rate).
export function lastIndexAtOrBefore(points, t, time = (p) => p.t) {
  let lo = 0;
  let hi = points.length - 1;
  let found = -1;
  while (lo <= hi) {
    const mid = (lo + hi) >> 1;
    if (time(points[mid]) <= t) { found = mid; lo = mid + 1; } else hi = mid - 1;
  }
  return found;
}

export const lastAtOrBefore = (points, t) => {
  const i = lastIndexAtOrBefore(points, t);
  return i < 0 ? null : points[i];
};

// ask(key) asks fetchFor(key) unless that key was the last asked; one request at a time, and
// while one runs only the newest key waits (a slider dragged past twenty frames asks for two).
// At most one request every minGapMs, so playing at 10x does not become a stream of requests.
export function newestOnly(fetchFor, onAnswer, onError, { minGapMs = 0 } = {}) {
  let running = false;
  let waiting = null;
  let last = null;
  let startedAt = 0;
  async function run(key) {
    running = true;
    last = key;
    startedAt = performance.now();
    try {
      onAnswer(await fetchFor(key), key);
    } catch (err) {
      onError(err, key);
    }
    const pause = Math.max(0, minGapMs - (performance.now() - startedAt));
    setTimeout(() => {
      running = false;
      const next = waiting;
      waiting = null;
      if (next !== null && next !== last) run(next);
    }, pause);
  }
  return function ask(key) {
    if (running) { waiting = key; return; }
    if (key === last) return;
    run(key);
  };
}
