// The robot on the GPS map: its fix as a dot coloured by fix quality (NavSatStatus), its heading
// as an arrow on the dot, its horizontal accuracy as a circle (one standard deviation, from
// NavSatFix.position_covariance), and its recent track. Channels: `fix` and `heading`.
import { fmtLatLng } from './gps_map.js';
import { _, formatUnit, said } from '../core/i18n.js';

const EMPTY = { type: 'FeatureCollection', features: [] };
const EARTH_RADIUS_M = 6371008.8;
const CIRCLE_STEPS = 64;
const QUALITY_TEXT = { none: _('no fix'), fix: _('GPS fix'), sbas: _('SBAS fix'), gbas: _('GBAS fix (DGPS/RTK)') };

export const ROBOT_SOURCES = { track: { type: 'geojson', data: EMPTY }, accuracy: { type: 'geojson', data: EMPTY } };
export const ROBOT_LAYERS = [
  { id: 'accuracy-fill', type: 'fill', source: 'accuracy', paint: { 'fill-color': '#58a6ff', 'fill-opacity': 0.18 } },
  { id: 'accuracy-line', type: 'line', source: 'accuracy', paint: { 'line-color': '#58a6ff', 'line-width': 1.5 } },
  { id: 'track', type: 'line', source: 'track', layout: { 'line-cap': 'round', 'line-join': 'round' },
    paint: { 'line-color': '#58a6ff', 'line-width': 3, 'line-opacity': 0.85 } },
];

// A circle of radius_m metres around (lng, lat) as a GeoJSON polygon, on a local flat earth:
// exact to well under a centimetre for the metres a GPS error spans.
export function circle(lng, lat, radiusM) {
  const dLat = (radiusM / EARTH_RADIUS_M) * (180 / Math.PI);
  const dLng = dLat / Math.cos((lat * Math.PI) / 180);
  const ring = [];
  for (let i = 0; i <= CIRCLE_STEPS; i += 1) {
    const a = (2 * Math.PI * i) / CIRCLE_STEPS;
    ring.push([lng + dLng * Math.cos(a), lat + dLat * Math.sin(a)]);
  }
  return { type: 'Feature', properties: { radius_m: radiusM }, geometry: { type: 'Polygon', coordinates: [ring] } };
}

// out: the text element that says where the robot is; quality: the pill that says how well.
export function createRobot(out, quality) {
  let map = null;
  let loaded = false;
  let marker = null;
  let fix = null;
  let heading = null;

  function sources() {
    const track = fix && fix.track.length > 1
      ? [{ type: 'Feature', properties: {}, geometry: { type: 'LineString', coordinates: fix.track } }] : [];
    const accuracy = fix && fix.fix && Number.isFinite(fix.accuracy_m) && fix.accuracy_m > 0
      ? [circle(fix.lng, fix.lat, fix.accuracy_m)] : [];
    return { track: { type: 'FeatureCollection', features: track }, accuracy: { type: 'FeatureCollection', features: accuracy } };
  }

  function drawHeading() {
    if (!marker) return;
    const node = marker.getElement();
    const shown = heading && !heading.stale && Number.isFinite(heading.heading_deg);
    node.dataset.heading = shown ? 'yes' : 'no';
    node.dataset.bearing = shown ? String(heading.heading_deg) : '';
    marker.setRotation(shown ? heading.heading_deg : 0);
  }

  function draw() {
    if (!map) return;
    if (fix && fix.fix) {
      if (!marker) {
        const node = document.createElement('div');
        node.className = 'wp-robot';
        node.title = _('robot (GPS fix)');
        node.append(Object.assign(document.createElement('span'), { className: 'wp-robot-heading' }));
        marker = new maplibregl.Marker({ element: node, rotationAlignment: 'map' }).setLngLat([fix.lng, fix.lat]).addTo(map);
      }
      marker.setLngLat([fix.lng, fix.lat]);
      marker.getElement().dataset.fix = 'yes';
      marker.getElement().dataset.quality = fix.quality || 'fix';
    } else if (marker) {
      marker.getElement().dataset.fix = 'no';  // kept where it was last known, greyed: never at 0,0
      marker.getElement().dataset.quality = 'none';
    }
    drawHeading();
    if (!loaded) return;
    const data = sources();
    map.getSource('track').setData(data.track);
    map.getSource('accuracy').setData(data.accuracy);
  }

  function showText() {
    if (!fix) return;
    out.dataset.fix = fix.fix ? 'yes' : 'no';
    if (fix.fix) {
      out.dataset.lng = String(fix.lng);
      out.dataset.lat = String(fix.lat);
      out.textContent = fmtLatLng(fix.lat, fix.lng) + (fix.accuracy_m !== null ? ` ±${formatUnit(fix.accuracy_m, 'm')}` : '');
      // The robot's centre (the antenna's offset taken out through TF), or the antenna as it reported.
      out.dataset.placed = fix.placed_by || 'antenna';
      out.title = fix.placed_by === 'tf'
        ? _('base_link, placed by TF from the antenna %(offset)s m off it', { offset: JSON.stringify(fix.antenna_offset_m) })
        : _("the antenna's own position (no TF for its frame)");
    } else {
      delete out.dataset.lng;
      delete out.dataset.lat;
      out.textContent = _('no fix (%(reason)s)', { reason: said(fix, 'reason') });
    }
    const q = fix.fix ? fix.quality || 'fix' : 'none';
    quality.dataset.quality = q;
    quality.textContent = QUALITY_TEXT[q] || fix.status_text;
    quality.title = `NavSatStatus ${fix.status} (${fix.status_text})`;
  }

  return {
    attach(m) { map = m; draw(); },
    loaded() { loaded = true; draw(); },
    showFix(next) {
      if (!next) return;
      fix = next;
      showText();
      draw();
    },
    showHeading(next) {
      if (!next) return;
      heading = next;
      const el = document.getElementById('wp-heading');
      if (el) {
        el.textContent = heading.stale ? `— ${_('(nothing on %(topic)s lately)', { topic: heading.topic })}`
          : formatUnit(Math.round(heading.heading_deg), '°');
        el.dataset.stale = heading.stale ? 'yes' : 'no';
        el.dataset.placed = heading.placed_by || 'message';
        el.title = heading.placed_by === 'tf' ? _("the sensor's mount on the robot taken out through TF")
          : _('as %(topic)s reports it', { topic: heading.topic });
      }
      drawHeading();
    },
  };
}
