// Where a display choice is kept in the browser: the cookie the server renders the next page
// from (rover_web/prefs: rover_web_theme, rover_web_lang) and localStorage. A year, the whole
// site (path=/: every robot's pages under one app), never sent to another site.
const COOKIES = { theme: 'rover_web_theme', language: 'rover_web_lang' };
const YEAR_S = 365 * 24 * 3600;

export function rememberChoice(key, value) {
  document.cookie = `${COOKIES[key]}=${encodeURIComponent(value)}; path=/; max-age=${YEAR_S}; SameSite=Strict`;
  try { localStorage.setItem(`rover_web.${key}`, value); } catch { /* storage off: the cookie keeps it */ }
}

// Plots, maps and the 3D view read their colours from the theme's CSS variables
// (static/js/core/theme.js) and redraw on this event.
export function applyTheme(value) {
  document.documentElement.dataset.theme = value;
  window.dispatchEvent(new CustomEvent('rover-theme', { detail: value }));
}
