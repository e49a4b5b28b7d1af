// The geofence on the GPS map: keep-in areas outlined, keep-out areas filled, and a small editor
// (draw a polygon, drag its vertices, delete it, import a GeoJSON file). Built on MapLibre's own
// GeoJSON sources, layers and draggable markers: no drawing library to vendor, and the server
// stays the judge — every edit is a local draft until "Save fence" PUTs it to /api/geofence,
// whose refusal (400 with the feature named, 403 below admin) is shown as it is. Below admin the
// page renders the editor's fieldset disabled with the reason (templates/panels/waypoints.html);
// a role lowered after the page loaded still meets the server's 403, in the server's words.
import { api } from '../core/api.js';
import { on } from '../live/live.js';
import { _, ngettext, formatList } from '../core/i18n.js';

const EMPTY = { type: 'FeatureCollection', features: [] };
const KIND_TITLES = { keep_in: _('keep-in'), keep_out: _('keep-out') };

function $(id) { return document.getElementById(id); }

const closeRing = (points) => [...points, points[0]];

// Even-odd ray casting in lng/lat: fine at the scale of a fence, and it answers from the draft
// itself, so a click selects the area even while MapLibre is still re-tiling the source after
// a save (queryRenderedFeatures then saw nothing and the click silently selected nothing).
function inRing(ring, [x, y]) {
  let inside = false;
  for (let i = 0, j = ring.length - 1; i < ring.length; j = i++) {
    const [xi, yi] = ring[i];
    const [xj, yj] = ring[j];
    if ((yi > y) !== (yj > y) && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}

function contains(geometry, point) {
  const polygons = geometry.type === 'Polygon' ? [geometry.coordinates] : geometry.coordinates;
  return polygons.some(([outer, ...holes]) => inRing(outer, point) && !holes.some((h) => inRing(h, point)));
}

// Keep-out areas are drawn on top, so they are picked first; among equals, the latest drawn.
function areaAt(features, point) {
  for (const kind of ['keep_out', 'keep_in']) {
    for (let i = features.length - 1; i >= 0; i -= 1) {
      if (features[i].properties.kind === kind && contains(features[i].geometry, point)) return i;
    }
  }
  return -1;
}

export function attachGeofence(map) {
  const box = $('gf-editor');
  if (!box) return { handleClick: () => false };
  const message = $('gf-message');
  const editToggle = $('gf-edit');
  let fence = JSON.parse($('gf-fence').textContent);  // the server's, with its revision
  let draft = structuredClone(fence.features);         // what is drawn and edited
  let dirty = false;
  let selected = -1;
  let drawing = null;  // { kind, points: [[lng, lat], ...] } while drawing
  let loaded = false;
  let vertexMarkers = [];

  const say = (text, kind = '') => { message.textContent = text; message.dataset.kind = kind; };
  const editing = () => editToggle.checked || drawing !== null;

  function setDirty(value) {
    dirty = value;
    box.dataset.dirty = value ? 'yes' : 'no';
    $('gf-save').disabled = !value;
    $('gf-revert').disabled = !value;
  }

  // --- drawing on the map ---

  function collection() {
    return { type: 'FeatureCollection',
      features: draft.map((f, i) => ({ ...f, properties: { ...f.properties, selected: i === selected } })) };
  }

  function draftShape() {
    if (!drawing || !drawing.points.length) return EMPTY;
    const pts = drawing.points;
    const features = pts.map((p) => ({ type: 'Feature', properties: {}, geometry: { type: 'Point', coordinates: p } }));
    if (pts.length > 1) {
      features.push({ type: 'Feature', properties: {},
        geometry: { type: 'LineString', coordinates: pts.length > 2 ? closeRing(pts) : pts } });
    }
    return { type: 'FeatureCollection', features };
  }

  function redraw() {
    box.dataset.areas = String(draft.length);
    box.dataset.mode = drawing ? `draw-${drawing.kind}` : editToggle.checked ? 'edit' : 'view';
    $('gf-finish').disabled = !drawing || drawing.points.length < 3;
    $('gf-delete').disabled = selected < 0;
    $('gf-count').textContent = draft.length
      ? formatList(draft.map((f) => (f.properties.name
        ? _('%(kind)s "%(name)s"', { kind: KIND_TITLES[f.properties.kind], name: f.properties.name })
        : KIND_TITLES[f.properties.kind])), { style: 'short', type: 'unit' })
      : _('no fence: waypoints are allowed anywhere');
    if (!loaded) return;
    map.getSource('fence').setData(collection());
    map.getSource('fence-draft').setData(draftShape());
    drawVertices();
  }

  // The selected polygon's vertices are draggable markers (only Polygons: a MultiPolygon is
  // moved by re-importing it). The closing vertex follows the first.
  function drawVertices() {
    for (const m of vertexMarkers) m.remove();
    vertexMarkers = [];
    const feature = draft[selected];
    if (!feature || feature.geometry.type !== 'Polygon' || drawing) return;
    feature.geometry.coordinates.forEach((ring, r) => {
      ring.slice(0, -1).forEach((point, v) => {
        const node = document.createElement('div');
        node.className = 'gf-vertex';
        node.title = _('drag to move this vertex');
        const marker = new maplibregl.Marker({ element: node, draggable: true }).setLngLat(point).addTo(map);
        marker.on('dragend', () => {
          const { lng, lat } = marker.getLngLat().wrap();
          ring[v] = [lng, lat];
          if (v === 0) ring[ring.length - 1] = [lng, lat];
          feature.geometry.coordinates[r] = ring;
          setDirty(true);
          redraw();
        });
        vertexMarkers.push(marker);
      });
    });
  }

  function addLayers() {
    map.addSource('fence', { type: 'geojson', data: collection() });
    map.addSource('fence-draft', { type: 'geojson', data: EMPTY });
    const before = map.getLayer('track') ? 'track' : undefined;
    const isKind = (kind) => ['==', ['get', 'kind'], kind];
    map.addLayer({ id: 'fence-keep-in-fill', type: 'fill', source: 'fence', filter: isKind('keep_in'),
      paint: { 'fill-color': '#3fb950', 'fill-opacity': 0.04 } }, before);
    map.addLayer({ id: 'fence-keep-in-line', type: 'line', source: 'fence', filter: isKind('keep_in'),
      paint: { 'line-color': '#3fb950', 'line-width': ['case', ['get', 'selected'], 4, 2.5], 'line-dasharray': [3, 2] } },
    before);
    map.addLayer({ id: 'fence-keep-out-fill', type: 'fill', source: 'fence', filter: isKind('keep_out'),
      paint: { 'fill-color': '#f85149', 'fill-opacity': 0.35 } }, before);
    map.addLayer({ id: 'fence-keep-out-line', type: 'line', source: 'fence', filter: isKind('keep_out'),
      paint: { 'line-color': '#f85149', 'line-width': ['case', ['get', 'selected'], 4, 2] } }, before);
    map.addLayer({ id: 'fence-draft-line', type: 'line', source: 'fence-draft', filter: ['==', ['geometry-type'], 'LineString'],
      paint: { 'line-color': '#e3b341', 'line-width': 2, 'line-dasharray': [2, 1] } });
    map.addLayer({ id: 'fence-draft-points', type: 'circle', source: 'fence-draft', filter: ['==', ['geometry-type'], 'Point'],
      paint: { 'circle-radius': 5, 'circle-color': '#e3b341', 'circle-stroke-color': '#fff', 'circle-stroke-width': 1 } });
    loaded = true;
    box.dataset.ready = 'yes';
    redraw();
  }

  // --- editing ---

  function handleClick(e) {
    if (box.disabled || !editing()) return false;
    const { lng, lat } = e.lngLat.wrap();
    if (drawing) {
      drawing.points.push([lng, lat]);
      say(ngettext('%(num)d vertex: click on, then "Finish area"', '%(num)d vertices: click on, then "Finish area"',
        drawing.points.length));
    } else {
      selected = areaAt(draft, [lng, lat]);
      say(selected >= 0 ? _('Area selected: drag its vertices, or delete it') : '');
    }
    redraw();
    return true;  // in edit mode a click never adds a waypoint
  }

  function startDrawing(kind) {
    drawing = { kind, points: [] };
    selected = -1;
    say(_('Drawing a %(kind)s area: click its corners on the map', { kind: KIND_TITLES[kind] }));
    redraw();
  }

  function finish() {
    if (!drawing || drawing.points.length < 3) return;
    draft.push({ type: 'Feature', properties: { kind: drawing.kind },
      geometry: { type: 'Polygon', coordinates: [closeRing(drawing.points)] } });
    selected = draft.length - 1;
    drawing = null;
    setDirty(true);
    say(_('Area added: "Save fence" to make the server enforce it'));
    redraw();
  }

  function show(collectionFromServer) {
    fence = collectionFromServer;
    draft = structuredClone(fence.features);
    selected = -1;
    drawing = null;
    setDirty(false);
    box.dataset.revision = String(fence.revision);
    redraw();
  }

  async function save(body, what) {
    try {
      const reply = await api('PUT', '/api/geofence', body);
      show(reply);
      say(ngettext('%(what)s: the fence has %(num)d area (revision %(revision)s)',
        '%(what)s: the fence has %(num)d areas (revision %(revision)s)', reply.features.length,
        { what, revision: reply.revision }));
    } catch (err) {
      say(_('Fence not saved: %(reason)s', { reason: err.message }), 'error');
    }
  }

  const strip = (f) => ({ type: 'Feature', geometry: f.geometry,
    properties: Object.fromEntries(Object.entries(f.properties).filter(([k]) => k === 'kind' || k === 'name')) });

  $('gf-draw-in').addEventListener('click', () => startDrawing('keep_in'));
  $('gf-draw-out').addEventListener('click', () => startDrawing('keep_out'));
  $('gf-finish').addEventListener('click', finish);
  editToggle.addEventListener('change', () => { if (!editToggle.checked) { selected = -1; drawing = null; } redraw(); });
  $('gf-delete').addEventListener('click', () => {
    if (selected < 0) return;
    draft.splice(selected, 1);
    selected = -1;
    setDirty(true);
    say(_('Area deleted: "Save fence" to make it so'));
    redraw();
  });
  $('gf-save').addEventListener('click', () => save({ type: 'FeatureCollection', features: draft.map(strip) }, _('Saved')));
  $('gf-revert').addEventListener('click', () => { show(fence); say(_('Changes dropped')); });
  $('gf-import').addEventListener('change', async (ev) => {
    const file = ev.target.files[0];
    ev.target.value = '';
    if (file) await save(await file.text(), _('Imported %(file)s', { file: file.name }));
  });
  document.addEventListener('keydown', (ev) => {
    if (ev.key === 'Escape' && drawing) { drawing = null; say(_('Drawing cancelled')); redraw(); }
  });

  // Another operator saved a fence: show theirs, unless this page has unsaved changes.
  on('geofence', async (state) => {
    if (state.revision === fence.revision) return;
    let latest;
    try { latest = await api('GET', '/api/geofence'); } catch { return; /* the next event retries */ }
    // This page's own save may have answered while the GET was out: then it shows that fence already,
    // and showing it again would drop what the operator selected since.
    if (latest.revision === fence.revision) return;
    if (!dirty) { show(latest); return; }
    fence = latest;  // keep the draft; "Revert" shows theirs
    say(_('The fence was changed elsewhere; "Revert" shows the new one'), 'error');
  });

  setDirty(false);
  box.dataset.revision = String(fence.revision);
  if (map.loaded()) addLayers(); else map.on('load', addLayers);
  return { handleClick };
}
