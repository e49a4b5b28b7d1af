// The page's theme for what CSS does not paint: canvas plots, map styles, the 3D view. Colours come
// from the theme's CSS variables (static/css/app.css), so a theme is defined once.
const root = document.documentElement;

// A variable's value, e.g. themeColour('--plot-axis'); the fallback when the style sheet has none.
// Cached until the theme changes: plots ask on every frame they draw.
const cache = new Map();
export function themeColour(name, fallback = '#888') {
  if (!cache.has(name)) cache.set(name, getComputedStyle(root).getPropertyValue(name).trim());
  return cache.get(name) || fallback;
}

// The n-th series colour of plots (--plot-1 ... --plot-8), distinct in both themes.
export const seriesColour = (i) => themeColour(`--plot-${(i % 8) + 1}`);

// uPlot reads these functions at every draw, so a chart follows a theme change on its next redraw.
export const plotAxes = (size) => [0, 1].map((i) => ({
  stroke: () => themeColour('--plot-axis'), grid: { stroke: () => themeColour('--plot-grid') },
  ticks: { stroke: () => themeColour('--plot-grid') }, ...(i === 1 ? { size } : {}),
}));

// The effective theme: 'dark' or 'daylight' ("auto" resolved by the browser's preference).
export function effectiveTheme() {
  const chosen = root.dataset.theme || 'auto';
  if (chosen !== 'auto') return chosen;
  return window.matchMedia('(prefers-color-scheme: light)').matches ? 'daylight' : 'dark';
}

// Calls fn whenever the effective theme may have changed: a choice in the Display menu, or the
// device switching between light and dark while the theme is "auto".
export function onThemeChange(fn) {
  window.addEventListener('rover-theme', () => fn(effectiveTheme()));
  window.matchMedia('(prefers-color-scheme: light)').addEventListener('change', () => fn(effectiveTheme()));
}
// The cache goes first, before any listener redraws.
onThemeChange(() => cache.clear());
