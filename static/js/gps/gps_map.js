// The GPS map the waypoints panel and the fleet page share: MapLibre with a style of our own, so
// nothing is fetched but from this app: raster tiles of a local store and drawn GeoJSON basemaps
// (rover_web/basemap), a graticule to read positions by, and the same controls everywhere.
// maplibregl is the vendored global (static/vendor/maplibre-gl-*), loaded with `defer`.
import { effectiveTheme, onThemeChange, themeColour } from '../core/theme.js';
import { _ } from '../core/i18n.js';

// Coordinates keep the decimal point and N/S/E/W whatever the page's language (ISO 6709's letters):
// operators read them into other tools as they are.
export function fmtLatLng(lat, lng) {
  const ns = lat >= 0 ? 'N' : 'S';
  const ew = lng >= 0 ? 'E' : 'W';
  return `${Math.abs(lat).toFixed(7)}° ${ns}, ${Math.abs(lng).toFixed(7)}° ${ew}`;
}

const EMPTY = { type: 'FeatureCollection', features: [] };

// Drawn basemaps (rover_web/basemap/features.py): each feature's properties.kind picks its look.
// Areas first, then lines, so a path along a shore stays visible; muted colours under the robot's.
export const FEATURE_COLORS = {
  land: '#2b3a2e', park: '#2f4a33', wetland: '#2e4a45', sand: '#5a5238', water: '#1d4f7a',
  pier: '#6e6a60', building: '#4a4f57', road: '#8a8f98', path: '#b7a98a', shore: '#5f9fd6',
};
// Daylight: a pale ground under dark lines, so the robot's and the plan's strong colours stand out
// in the sun as they do on the dark map.
const DAYLIGHT_COLORS = {
  land: '#e6ede1', park: '#cfe3c4', wetland: '#cde2dc', sand: '#eee2bb', water: '#9cc7ea',
  pier: '#b5ae9f', building: '#c4c8cf', road: '#5d636c', path: '#85704a', shore: '#1f5f9e',
};
const palette = () => (effectiveTheme() === 'daylight' ? DAYLIGHT_COLORS : FEATURE_COLORS);
const gridColour = (underlay) => (underlay ? '#00000033' : themeColour('--plot-axis', '#5b6b7b'));
const AREA_KINDS = ['land', 'park', 'wetland', 'sand', 'water', 'pier', 'building'];
const LINE_KINDS = ['shore', 'path', 'road'];
const colorOf = (kinds) => ['match', ['get', 'kind'], ...kinds.flatMap((k) => [k, palette()[k]]), '#888888'];

function featureLayers(source) {
  const area = ['in', ['geometry-type'], ['literal', ['Polygon', 'MultiPolygon']]];
  const line = ['in', ['geometry-type'], ['literal', ['LineString', 'MultiLineString']]];
  // Water above land: a lake drawn inside a land polygon must not be covered by it.
  return [
    { id: `${source}-land`, type: 'fill', source,
      filter: ['all', area, ['in', ['get', 'kind'], ['literal', AREA_KINDS.filter((k) => k !== 'water')]]],
      paint: { 'fill-color': colorOf(AREA_KINDS) } },
    { id: `${source}-water`, type: 'fill', source, filter: ['all', area, ['==', ['get', 'kind'], 'water']],
      paint: { 'fill-color': palette().water } },
    { id: `${source}-lines`, type: 'line', source,
      filter: ['all', line, ['in', ['get', 'kind'], ['literal', LINE_KINDS]]],
      layout: { 'line-cap': 'round', 'line-join': 'round' },
      paint: { 'line-color': colorOf(LINE_KINDS), 'line-width': ['match', ['get', 'kind'], 'road', 3, 1.5] } },
  ];
}

// cfg: the server's map config (center, zoom, basemap or null). sources/layers: the page's own,
// drawn above the basemap and the grid.
function buildStyle(cfg, sources, layers) {
  const style = {
    version: 8,
    sources: { graticule: { type: 'geojson', data: EMPTY }, ...sources },
    layers: [{ id: 'background', type: 'background', paint: { 'background-color': themeColour('--map-bg', '#17212b') } }],
  };
  // Drawn basemaps under the raster tiles: where a store has tiles (imagery, a real survey) they
  // win; beyond the store's bounds the drawn ones still show.
  const drawn = cfg.features || [];
  drawn.forEach((f, i) => {
    style.sources[`features-${i}`] = { type: 'geojson', data: f.url, attribution: f.attribution };
    style.layers.push(...featureLayers(`features-${i}`));
  });
  if (cfg.basemap) {
    const { name, ...source } = cfg.basemap;
    style.sources.basemap = { type: 'raster', ...source };
    style.layers.push({ id: 'basemap', type: 'raster', source: 'basemap' });
  }
  const underlay = cfg.basemap || drawn.length;
  style.layers.push(
    { id: 'graticule', type: 'line', source: 'graticule',
      paint: { 'line-color': gridColour(underlay), 'line-width': 1 } },
    ...layers,
  );
  return style;
}

const GRID_STEPS = [30, 10, 5, 2, 1, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001,
  0.0005, 0.0002, 0.0001, 0.00005, 0.00002, 0.00001];

function graticule(bounds) {
  const west = Math.max(-180, bounds.getWest());
  const east = Math.min(180, bounds.getEast());
  const south = Math.max(-85, bounds.getSouth());
  const north = Math.min(85, bounds.getNorth());
  const span = Math.max(east - west, north - south);
  const step = GRID_STEPS.find((s) => span / s >= 4) || GRID_STEPS[GRID_STEPS.length - 1];
  const features = [];
  const line = (coordinates) => features.push({ type: 'Feature', properties: {}, geometry: { type: 'LineString', coordinates } });
  for (let x = Math.ceil(west / step) * step; x <= east && features.length < 200; x += step) line([[x, south], [x, north]]);
  for (let y = Math.ceil(south / step) * step; y <= north && features.length < 400; y += step) line([[west, y], [east, y]]);
  return { type: 'FeatureCollection', features };
}

// MapLibre's own words (its canvas's label, its buttons' titles) in the page's language; its unit
// symbols stay as they are.
function mapLocale() {
  return {
    'Map.Title': _('Map'),
    'Marker.Title': _('Map marker'),
    'Popup.Close': _('Close popup'),
    'NavigationControl.ZoomIn': _('Zoom in'),
    'NavigationControl.ZoomOut': _('Zoom out'),
    'NavigationControl.ResetBearing': _('Drag to rotate map, click to reset north'),
    'AttributionControl.ToggleAttribution': _('Toggle attribution'),
    'AttributionControl.MapFeedback': _('Map feedback'),
  };
}

// The map in `container`, or throws when this browser cannot show one (no WebGL): callers keep
// their lists working without it. onLoad runs once the style is in (sources can be set), before
// container.dataset.ready becomes 'yes'.
export function createGpsMap(container, cfg, { sources = {}, layers = [], onLoad = () => {} } = {}) {
  const map = new maplibregl.Map({
    container, style: buildStyle(cfg, sources, layers), center: cfg.center, zoom: cfg.zoom,
    attributionControl: { compact: true }, dragRotate: false, pitchWithRotate: false, locale: mapLocale(),
  });
  map.touchZoomRotate.disableRotation();
  map.addControl(new maplibregl.NavigationControl({ showCompass: false }));
  map.addControl(new maplibregl.ScaleControl({ unit: 'metric' }));
  map.on('error', (e) => {
    // A tile the local store does not have is normal at its edges; anything else is a bug.
    if (e.sourceId === 'basemap' && e.error && e.error.status === 404) return;
    console.error('map error', e.error || e);
  });
  let loaded = false;
  const updateGrid = () => map.getSource('graticule').setData(graticule(map.getBounds()));
  map.on('load', () => {
    loaded = true;
    updateGrid();
    onLoad(map);
    container.dataset.ready = 'yes';
  });
  map.on('moveend', () => { if (loaded) updateGrid(); });
  // A theme change repaints the ground, the drawn basemaps and the grid; the page's own layers keep
  // their colours (strong in both themes).
  onThemeChange(() => {
    if (!loaded) return;
    map.setPaintProperty('background', 'background-color', themeColour('--map-bg', '#17212b'));
    (cfg.features || []).forEach((_, i) => {
      map.setPaintProperty(`features-${i}-land`, 'fill-color', colorOf(AREA_KINDS));
      map.setPaintProperty(`features-${i}-water`, 'fill-color', palette().water);
      map.setPaintProperty(`features-${i}-lines`, 'line-color', colorOf(LINE_KINDS));
    });
    map.setPaintProperty('graticule', 'line-color', gridColour(cfg.basemap || (cfg.features || []).length));
  });
  return map;
}
