// Heavy browser libraries (MapLibre is 1 MB) only on the pages and cards that show a map, and only
// after what matters on a slow link: once the page's own modules ran (the e-stop, the stick) and
// its event stream is live (the status bar), so their bytes do not queue behind the library's.
// The URLs (content-hashed) are the server's, on <body data-*> (templates/base.html).

import { _ } from './i18n.js';

const LIVE_WAIT_MS = 4000;  // no stream (a page without one, the server away): load anyway after this

const scripts = new Map();

export function afterLive() {
  const body = document.body;
  if (body.dataset.link === undefined || body.dataset.link === 'up') return Promise.resolve();
  return new Promise((resolve) => {
    const watch = new MutationObserver(() => { if (body.dataset.link === 'up') done(); });
    const timer = setTimeout(() => done(), LIVE_WAIT_MS);
    function done() { watch.disconnect(); clearTimeout(timer); resolve(); }
    watch.observe(body, { attributes: true, attributeFilter: ['data-link'] });
  });
}

export function loadScript(url) {
  if (!scripts.has(url)) {
    scripts.set(url, new Promise((resolve, reject) => {
      const el = document.createElement('script');
      el.src = url;
      el.onload = () => resolve();
      el.onerror = () => reject(new Error(_('%(url)s did not load', { url })));
      document.head.append(el);
    }));
  }
  return scripts.get(url);
}

export function loadStyle(url) {
  if (!url || document.querySelector(`link[rel="stylesheet"][href="${CSS.escape(url)}"]`)) return;
  const el = document.createElement('link');
  el.rel = 'stylesheet';
  el.href = url;
  document.head.append(el);
}

// A page with its own <script> for the library (the plot page, the hub) names no URL: wait for that
// script, which may run after this module (a page's bundle is in its head, the library's <script>
// at the end of its body), instead of asking for "undefined".
function loadOrAwait(url, name, global) {
  if (url) return loadScript(url);
  const own = document.querySelector(`script[src*="${name}"]`);
  if (!own || window[global]) return Promise.resolve();
  return new Promise((resolve, reject) => {
    own.addEventListener('load', () => resolve(), { once: true });
    own.addEventListener('error', () => reject(new Error(_('%(url)s did not load', { url: own.src }))), { once: true });
  });
}

// uPlot (window.uPlot), for the dashboard's plot cards and link plot; the plot page has its own <script>.
export async function loadUplot() {
  if (window.uPlot) return window.uPlot;
  const { uplotJs, uplotCss } = document.body.dataset;
  await afterLive();
  loadStyle(uplotCss);
  await loadOrAwait(uplotJs, 'uPlot', 'uPlot');
  return window.uPlot;
}

// MapLibre GL (window.maplibregl): a page that still has its own <script> for it gets it at once.
export async function loadMaplibre() {
  if (window.maplibregl) return window.maplibregl;
  const { maplibreJs, maplibreCss } = document.body.dataset;
  await afterLive();
  loadStyle(maplibreCss);
  await loadOrAwait(maplibreJs, 'maplibre-gl', 'maplibregl');
  return window.maplibregl;
}
