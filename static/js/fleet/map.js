// The fleet's GPS map, shared by the fleet page (fleet.js: the robots of one rover_web) and the hub's
// page (hub/page.js: robots heard over Zenoh): one marker per robot with a position, each a link to its
// own rover_web, framed until the operator moves the map. The page gives it GET /api/robots's robots
// on each poll. A robot the hub has lost (`heard: 'lost'`) stays where it was last seen, dimmed.
// Untrusted text (titles) only ever goes through textContent; a URL is followed only if http(s)
// (a path on this server is too). With many robots (a hub of 100) markers must not hide each other:
// a marker whose dot would cover another's moves to the nearest free place on rings around its
// point (each still opens its own robot), and past CROWDED markers the names show only on hover or focus.
// A robot the hub forgot leaves the map with the list.
import { createGpsMap, fmtLatLng } from '../gps/gps_map.js';
import { loadMaplibre } from '../core/vendor.js';
import { _ } from '../core/i18n.js';

// What a robot's summary words mean to people (rover_web/fleet/summary.py): its link, its mode, its e-stop.
export const LINK_WORDS = { ok: _('ok'), degraded: _('degraded'), stale: _('stale'), no_data: _('no data') };
export const MODE_WORDS = { estop: _('e-stop'), driving: _('driving'), operator: _('operator'), idle: _('idle') };
export const ESTOP_WORDS = { engaged: _('engaged'), released: _('released'), unknown: _('unknown') };

// 'engaged', 'released', or 'unknown' (a robot the hub has heard no summary from yet).
export function estopState(robot) {
  const engaged = robot.estop ? robot.estop.engaged : null;
  if (engaged === true) return 'engaged';
  return engaged === false ? 'released' : 'unknown';
}

// The robot's URL if it leads to a web page: the fleet page's are paths on this server, the hub's
// another server's http(s) URL; never javascript: or data:.
function webUrl(url) {
  if (typeof url !== 'string' || url === '') return null;
  try {
    return ['http:', 'https:'].includes(new URL(url, window.location.href).protocol) ? url : null;
  } catch {
    return null;
  }
}

function markerElement(robot) {
  const node = document.createElement('button');
  node.type = 'button';
  node.className = 'fleet-marker';
  node.dataset.robot = robot.name;
  const dot = document.createElement('span');
  dot.className = 'fleet-marker-dot';
  const name = document.createElement('span');
  name.className = 'fleet-marker-name';
  node.append(dot, name);
  // A marker is a link to its robot's own rover_web, by mouse, touch or keyboard.
  node.addEventListener('click', (e) => {
    e.stopPropagation();
    if (node.dataset.url) window.location.assign(node.dataset.url);
  });
  return node;
}

function showOnMarker(node, robot) {
  const url = webUrl(robot.url);
  const estop = estopState(robot);
  node.dataset.fix = 'yes';
  if (url) node.dataset.url = url; else delete node.dataset.url;
  node.dataset.estop = estop;
  node.dataset.link = robot.link;
  if (robot.heard) node.dataset.heard = robot.heard;  // the hub's: live or lost
  node.dataset.lng = String(robot.position.lng);
  node.dataset.lat = String(robot.position.lat);
  node.querySelector('.fleet-marker-name').textContent = robot.title;
  const parts = [_('%(robot)s: %(mode)s, e-stop %(estop)s',
    { robot: robot.title, mode: robot.mode ? MODE_WORDS[robot.mode] || robot.mode : '—', estop: ESTOP_WORDS[estop] })];
  if (robot.heard === 'lost') parts.push(_('lost: not heard lately'));
  parts.push(fmtLatLng(robot.position.lat, robot.position.lng));
  if (url) parts.push(_('click to open its dashboard'));
  node.title = parts.join(' · ');
  node.setAttribute('aria-label', url ? _('%(robot)s: open its dashboard', { robot: robot.title }) : robot.title);
}

// The map in `container` (its data-config: the server's map config), drawn once MapLibre has come;
// when this browser cannot show one, `note` says so and the page's table goes on alone.
// render(robots) places every robot; robots given before the map has loaded are placed once it has.
const CROWDED = 20;  // markers beyond which names are shown on hover and focus only
const APART_PX = 20;  // dots (14 px when crowded, 18 px else) kept at least this far apart

export function createFleetMap(container, note) {
  const markers = new Map();  // robot name -> maplibregl.Marker
  let userMoved = false;  // once the operator pans or zooms, the map stops framing the robots itself
  let framed = 0;         // how many robots had a position when the map last framed them
  let ready = false;
  let latest = [];
  let map;

  function place(robot) {
    let marker = markers.get(robot.name);
    if (!robot.position) {
      // Kept where it was last known, greyed: never drawn at 0,0.
      if (marker) marker.getElement().dataset.fix = 'no';
      return;
    }
    if (!marker) {
      marker = new maplibregl.Marker({ element: markerElement(robot), anchor: 'left', offset: [-9, 0] });
      marker.setLngLat([robot.position.lng, robot.position.lat]).addTo(map);
      markers.set(robot.name, marker);
    }
    marker.setLngLat([robot.position.lng, robot.position.lat]);
    showOnMarker(marker.getElement(), robot);
  }

  // Frame every robot with a position when one more of them has one, until the operator moves the map.
  function frame(robots) {
    const placed = robots.filter((r) => r.position);
    if (userMoved || placed.length <= framed) return;
    framed = placed.length;
    const bounds = new maplibregl.LngLatBounds();
    for (const r of placed) bounds.extend([r.position.lng, r.position.lat]);
    // More room on the right: each marker's name is drawn there. Less of it all on a small map.
    const side = Math.min(60, container.clientWidth / 8, container.clientHeight / 8);
    const padding = { top: side, bottom: side, left: side, right: Math.min(180, container.clientWidth / 3) };
    map.fitBounds(bounds, { padding, maxZoom: 17, duration: 0 });
  }

  // Dots that would overlap on screen: each marker, in name order, keeps its own point if it is free,
  // else takes the nearest free one on rings around it (6 on the first, 12 on the second, ...).
  function spread() {
    const placed = [];
    const free = (x, y) => placed.every(([px, py]) => Math.hypot(px - x, py - y) >= APART_PX);
    for (const name of [...markers.keys()].sort()) {
      const marker = markers.get(name);
      const p = map.project(marker.getLngLat());
      let at = [p.x, p.y];
      for (let ring = 1; !free(...at) && ring < 12; ring += 1) {
        const count = 6 * ring;
        for (let i = 0; i < count; i += 1) {
          const angle = (2 * Math.PI * i) / count;
          const candidate = [p.x + ring * APART_PX * Math.cos(angle), p.y + ring * APART_PX * Math.sin(angle)];
          if (free(...candidate)) { at = candidate; break; }
        }
      }
      placed.push(at);
      const dx = Math.round(at[0] - p.x);
      const dy = Math.round(at[1] - p.y);
      marker.setOffset([-9 + dx, dy]);
      marker.getElement().dataset.spread = dx || dy ? 'yes' : 'no';
    }
    container.classList.toggle('fleet-crowded', markers.size > CROWDED);
  }

  function render(robots) {
    latest = robots;
    if (!ready) return;
    const names = new Set(robots.map((r) => r.name));
    for (const [name, marker] of markers) {
      if (!names.has(name)) { marker.remove(); markers.delete(name); }  // forgotten by the hub
    }
    for (const robot of robots) place(robot);
    frame(robots);
    spread();
  }

  // MapLibre comes after the page is live (core/vendor.js); the table works before it.
  const fleetMap = { map: null, render };
  const noMap = (err) => {
    note.hidden = false;
    note.textContent = _('The map cannot be shown in this browser (%(reason)s); the table still works.', { reason: err.message });
  };
  loadMaplibre().then(() => {
    try {
      map = createGpsMap(container, JSON.parse(container.dataset.config), {
        onLoad: () => { ready = true; render(latest); },
      });
    } catch (err) {
      noMap(err);
      return;
    }
    fleetMap.map = map;
    window.roverFleetMap = map;  // for the browser tests and the curious operator's console
    for (const start of ['dragstart', 'zoomstart']) {
      map.on(start, (e) => { if (e.originalEvent) userMoved = true; });
    }
    map.on('zoomend', () => { if (ready) spread(); });
  }, noMap);
  return fleetMap;
}
