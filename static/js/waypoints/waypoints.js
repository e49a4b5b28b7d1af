// The GPS waypoints panel: MapLibre map (no remote sources), numbered draggable markers, the
// mission list, and the robot's fix with its track. The server owns the mission: every edit is an
// HTTP call, and what is drawn is whatever the `waypoints` channel (or a fresh GET) says, newest
// revision wins. Untrusted text (labels) only ever goes through textContent.
import { api } from '../core/api.js';
import { on } from '../live/live.js';
import { attachGeofence } from '../geofence/geofence_map.js';
import { createGpsMap, fmtLatLng } from '../gps/gps_map.js';
import { loadMaplibre } from '../core/vendor.js';
import { ROBOT_LAYERS, ROBOT_SOURCES, createRobot } from '../gps/robot.js';
import { _, ngettext, formatNumber } from '../core/i18n.js';

const el = document.getElementById('wp-map');
if (el) init(el);

function $(id) { return document.getElementById(id); }

function init(container) {
  const cfg = JSON.parse(container.dataset.config);
  const list = $('wp-list');
  const message = $('wp-message');
  const state = { mission: { revision: -1, waypoints: [] }, markers: new Map(), dragging: new Set() };
  let map = null;
  const robot = createRobot($('wp-fix'), $('wp-quality'));

  const say = (text, kind = '') => { message.textContent = text; message.dataset.kind = kind; };

  // --- the mission: list and markers ---

  function render(mission, force = false) {
    if (!mission || (!force && mission.revision < state.mission.revision)) return;
    state.mission = mission;
    list.dataset.revision = String(mission.revision);
    $('wp-count').textContent = formatNumber(mission.waypoints.length);
    list.replaceChildren(...mission.waypoints.map((w, i) => listItem(w, i, mission.waypoints.length)));
    if (map) drawMarkers(mission.waypoints);
  }

  function listItem(w, i, n) {
    const li = document.createElement('li');
    li.dataset.id = String(w.id);
    const num = document.createElement('span');
    num.className = 'wp-num';
    num.textContent = String(i + 1);
    const label = document.createElement('span');
    label.className = 'wp-label';
    label.textContent = w.label;
    const coords = document.createElement('span');
    coords.className = 'wp-coords';
    coords.textContent = fmtLatLng(w.lat, w.lng);
    const buttons = document.createElement('span');
    buttons.className = 'wp-buttons';
    const button = (text, title, fn, disabled = false) => {
      const b = document.createElement('button');
      b.type = 'button';
      b.textContent = text;
      b.title = title;
      b.disabled = disabled;
      b.addEventListener('click', fn);
      buttons.append(b);
    };
    button('↑', _('earlier in the mission'), () => edit('PATCH', w.id, { index: i - 1 }), i === 0);
    button('↓', _('later in the mission'), () => edit('PATCH', w.id, { index: i + 1 }), i === n - 1);
    button('✕', _('delete this waypoint'), () => edit('DELETE', w.id));
    li.append(num, label, coords, buttons);
    return li;
  }

  function markerElement() {
    const node = document.createElement('div');
    node.className = 'wp-marker';
    return node;
  }

  function drawMarkers(waypoints) {
    const seen = new Set();
    waypoints.forEach((w, i) => {
      seen.add(w.id);
      let marker = state.markers.get(w.id);
      if (!marker) {
        marker = new maplibregl.Marker({ element: markerElement(), draggable: true });
        marker.on('dragstart', () => state.dragging.add(w.id));
        marker.on('dragend', () => {
          state.dragging.delete(w.id);
          const { lng, lat } = marker.getLngLat().wrap();
          edit('PATCH', w.id, { lng, lat });
        });
        marker.setLngLat([w.lng, w.lat]).addTo(map);
        state.markers.set(w.id, marker);
      } else if (!state.dragging.has(w.id)) {
        marker.setLngLat([w.lng, w.lat]);
      }
      const key = JSON.stringify([i, w.label, w.lat, w.lng]);
      if (marker.wpKey === key) return;  // unchanged: keep an open popup open
      marker.wpKey = key;
      const node = marker.getElement();
      node.textContent = String(i + 1);
      node.dataset.id = String(w.id);
      node.title = `${i + 1}${w.label ? ` · ${w.label}` : ''} · ${fmtLatLng(w.lat, w.lng)}`;
      marker.setPopup(popupFor(w, i));
    });
    for (const [id, marker] of state.markers) {
      if (!seen.has(id)) { marker.remove(); state.markers.delete(id); }
    }
  }

  function popupFor(w, i) {
    const box = document.createElement('div');
    box.className = 'wp-popup';
    const title = document.createElement('strong');
    title.textContent = w.label ? _('Waypoint %(n)d: %(label)s', { n: i + 1, label: w.label }) : _('Waypoint %(n)d', { n: i + 1 });
    const where = document.createElement('div');
    where.textContent = fmtLatLng(w.lat, w.lng);
    const del = document.createElement('button');
    del.type = 'button';
    del.className = 'danger';
    del.textContent = _('Delete');
    del.addEventListener('click', () => edit('DELETE', w.id));
    box.append(title, where, del);
    return new maplibregl.Popup({ offset: 16, closeButton: true }).setDOMContent(box);
  }

  async function refresh() {
    try { render(await api('GET', '/api/waypoints')); } catch (err) { say(_('Could not reload the list: %(reason)s', { reason: err.message }), 'error'); }
  }

  async function edit(method, id, body) {
    try {
      await api(method, `/api/waypoints/${id}`, body);
      say('');
    } catch (err) {
      say(err.message, 'error');
      render(state.mission, true);  // a refused drag snaps back
    }
    await refresh();
  }

  async function addAt(lngLat) {
    const { lng, lat } = lngLat.wrap();
    try {
      const res = await api('POST', '/waypoints', { lng, lat });
      say(_('Waypoint %(n)d added at %(position)s', { n: res.waypoint.index + 1, position: fmtLatLng(res.waypoint.lat, res.waypoint.lng) }));
    } catch (err) {
      say(err.message, 'error');
    }
    await refresh();
  }

  $('wp-send').addEventListener('click', async () => {
    try {
      const res = await api('POST', '/api/waypoints/send', { revision: state.mission.revision });
      say(ngettext('Mission of %(num)d waypoint sent on %(topic)s', 'Mission of %(num)d waypoints sent on %(topic)s', res.sent,
        { topic: res.topic }));
    } catch (err) { say(err.message, 'error'); }
  });
  $('wp-clear').addEventListener('click', async () => {
    const n = state.mission.waypoints.length;
    if (!n || !window.confirm(ngettext('Delete the %(num)d waypoint?', 'Delete all %(num)d waypoints?', n))) return;
    try { await api('DELETE', '/api/waypoints'); say(_('All waypoints deleted')); } catch (err) { say(err.message, 'error'); }
    await refresh();
  });
  $('wp-import').addEventListener('change', async (ev) => {
    const file = ev.target.files[0];
    ev.target.value = '';
    if (!file) return;
    try {
      const res = await api('POST', '/api/waypoints/geojson', await file.text());
      say(ngettext('Imported %(num)d waypoint from %(file)s', 'Imported %(num)d waypoints from %(file)s', res.count,
        { file: file.name }));
    } catch (err) { say(`${file.name}: ${err.message}`, 'error'); }
    await refresh();
  });

  // --- the map: MapLibre comes after the page is live (core/vendor.js); the list works before it ---

  function noMap(err) {
    const note = $('wp-map-note');
    note.hidden = false;
    note.textContent = _('The map cannot be shown in this browser (%(reason)s); the list still works.', { reason: err.message });
    map = null;
  }

  function attachMap() {
    try {
      map = createGpsMap(container, cfg, {
        sources: ROBOT_SOURCES,
        layers: ROBOT_LAYERS,
        onLoad: () => robot.loaded(),
      });
      robot.attach(map);
    } catch (err) {
      noMap(err);
      return;
    }
    const geofence = attachGeofence(map);
    map.on('click', (e) => {
      const target = e.originalEvent && e.originalEvent.target;
      if (target && target.closest && target.closest('.maplibregl-marker, .maplibregl-popup')) return;
      if (geofence.handleClick(e)) return;  // editing the fence
      addAt(e.lngLat);
    });
    map.on('mousemove', (e) => { $('wp-cursor').textContent = fmtLatLng(e.lngLat.lat, e.lngLat.lng); });
    window.roverWaypointsMap = map;  // for the browser tests and the curious operator's console
    render(state.mission, true);  // the markers of what the list already shows
  }
  loadMaplibre().then(attachMap, noMap);

  render(JSON.parse($('wp-mission').textContent));
  robot.showFix(JSON.parse($('wp-fix-state').textContent));
  robot.showHeading(JSON.parse($('wp-heading-state').textContent));
  on('waypoints', (mission) => render(mission));
  on('fix', robot.showFix);
  on('heading', robot.showHeading);
}
