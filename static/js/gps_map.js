// The GPS map the waypoints panel and the fleet page share: MapLibre with a style of our own, so
// nothing is fetched unless a local basemap is installed (rover_web/basemap: the app serves its
// tiles), a graticule to read positions by without one, and the same controls everywhere.
// maplibregl is the vendored global (static/vendor/maplibre-gl-*), loaded with `defer`.

export function fmtLatLng(lat, lng) {
  const ns = lat >= 0 ? 'N' : 'S';
  const ew = lng >= 0 ? 'E' : 'W';
  return `${Math.abs(lat).toFixed(7)}° ${ns}, ${Math.abs(lng).toFixed(7)}° ${ew}`;
}

const EMPTY = { type: 'FeatureCollection', features: [] };

// cfg: the server's map config (center, zoom, basemap or null). sources/layers: the page's own,
// drawn above the basemap and the grid.
function buildStyle(cfg, sources, layers) {
  const style = {
    version: 8,
    sources: { graticule: { type: 'geojson', data: EMPTY }, ...sources },
    layers: [{ id: 'background', type: 'background', paint: { 'background-color': '#17212b' } }],
  };
  if (cfg.basemap) {
    const { name, ...source } = cfg.basemap;
    style.sources.basemap = { type: 'raster', ...source };
    style.layers.push({ id: 'basemap', type: 'raster', source: 'basemap' });
  }
  style.layers.push(
    { id: 'graticule', type: 'line', source: 'graticule',
      paint: { 'line-color': cfg.basemap ? '#00000033' : '#5b6b7b', 'line-width': 1 } },
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

// The map in `container`, or throws when this browser cannot show one (no WebGL): callers keep
// their lists working without it. onLoad runs once the style is in (sources can be set), before
// container.dataset.ready becomes 'yes'.
export function createGpsMap(container, cfg, { sources = {}, layers = [], onLoad = () => {} } = {}) {
  const map = new maplibregl.Map({
    container, style: buildStyle(cfg, sources, layers), center: cfg.center, zoom: cfg.zoom,
    attributionControl: { compact: true }, dragRotate: false, pitchWithRotate: false,
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
  return map;
}
