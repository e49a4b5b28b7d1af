// The scan, the footprint, the recent path and markers, drawn in screen space from map metres.

export const LAYER_COLORS = { scan: '#ff3b30', footprint: '#e3b341', path: '#58a6ff' };
const SCAN_DOT_PX = 3;

// Each bin's nearest return as a filled dot; its farthest (a doorway, a long beam between walls),
// sent only where it stands out, as a hollow one, so the two read apart.
export function drawScan(ctx, toScreen, scan) {
  const p = scan.points;
  ctx.fillStyle = LAYER_COLORS.scan;
  const half = SCAN_DOT_PX / 2;
  for (let i = 0; i + 1 < p.length; i += 2) {
    const [sx, sy] = toScreen(p[i], p[i + 1]);
    ctx.fillRect(sx - half, sy - half, SCAN_DOT_PX, SCAN_DOT_PX);
  }
  const far = scan.far_points || [];
  if (far.length) {
    ctx.strokeStyle = LAYER_COLORS.scan;
    ctx.lineWidth = 1;
    ctx.beginPath();
    for (let i = 0; i + 1 < far.length; i += 2) {
      const [sx, sy] = toScreen(far[i], far[i + 1]);
      ctx.rect(sx - half - 0.5, sy - half - 0.5, SCAN_DOT_PX + 1, SCAN_DOT_PX + 1);
    }
    ctx.stroke();
  }
  return (p.length + far.length) / 2;
}

function polyline(ctx, toScreen, points, close) {
  ctx.beginPath();
  points.forEach(([x, y], i) => {
    const [sx, sy] = toScreen(x, y);
    if (i === 0) ctx.moveTo(sx, sy); else ctx.lineTo(sx, sy);
  });
  if (close) ctx.closePath();
}

export function drawFootprint(ctx, toScreen, footprint) {
  ctx.strokeStyle = LAYER_COLORS.footprint;
  ctx.fillStyle = `${LAYER_COLORS.footprint}40`;
  ctx.lineWidth = 2;
  polyline(ctx, toScreen, footprint.polygon, true);
  ctx.fill();
  ctx.stroke();
}

export function drawPath(ctx, toScreen, points) {
  if (points.length < 2) return;
  ctx.strokeStyle = LAYER_COLORS.path;
  ctx.lineWidth = 2;
  ctx.lineJoin = 'round';
  ctx.setLineDash([6, 4]);
  polyline(ctx, toScreen, points, false);
  ctx.stroke();
  ctx.setLineDash([]);
}

const css = ([r, g, b, a]) => `rgba(${Math.round(r * 255)}, ${Math.round(g * 255)}, ${Math.round(b * 255)}, ${a})`;

// Markers come projected into the map frame by the server; sizes are metres, turned into pixels
// with pxPerM, never below what one can see.
export function drawMarker(ctx, toScreen, pxPerM, m) {
  const colour = css(m.color);
  const size = (metres, least = 2) => Math.max(least, metres * pxPerM);
  const [sx, sy] = toScreen(m.pose[0], m.pose[1]);
  ctx.fillStyle = colour;
  ctx.strokeStyle = colour;
  switch (m.type) {
    case 'sphere': case 'cylinder':
      ctx.beginPath();
      ctx.arc(sx, sy, size(m.scale[0] / 2), 0, 2 * Math.PI);
      ctx.fill();
      break;
    case 'cube': {
      const w = size(m.scale[0]), h = size(m.scale[1]);
      ctx.save();
      ctx.translate(sx, sy);
      ctx.rotate(-m.pose[2]);
      ctx.fillRect(-w / 2, -h / 2, w, h);
      ctx.restore();
      break;
    }
    case 'arrow': {
      let from = [sx, sy];
      let to;
      if (m.points.length >= 2) {
        from = toScreen(...m.points[0]);
        to = toScreen(...m.points[1]);
      } else {
        to = toScreen(m.pose[0] + Math.cos(m.pose[2]) * m.scale[0], m.pose[1] + Math.sin(m.pose[2]) * m.scale[0]);
      }
      const angle = Math.atan2(to[1] - from[1], to[0] - from[0]);
      const head = Math.max(6, Math.hypot(to[0] - from[0], to[1] - from[1]) * 0.3);
      ctx.lineWidth = size(m.points.length >= 2 ? m.scale[0] : m.scale[1], 2);
      ctx.beginPath();
      ctx.moveTo(...from);
      ctx.lineTo(...to);
      ctx.stroke();
      ctx.beginPath();
      ctx.moveTo(...to);
      ctx.lineTo(to[0] - head * Math.cos(angle - 0.45), to[1] - head * Math.sin(angle - 0.45));
      ctx.lineTo(to[0] - head * Math.cos(angle + 0.45), to[1] - head * Math.sin(angle + 0.45));
      ctx.closePath();
      ctx.fill();
      break;
    }
    case 'line_strip': case 'line_list':
      ctx.lineWidth = size(m.scale[0], 1);
      ctx.beginPath();
      m.points.forEach(([x, y], i) => {
        const [px, py] = toScreen(x, y);
        if (i === 0 || (m.type === 'line_list' && i % 2 === 0)) ctx.moveTo(px, py); else ctx.lineTo(px, py);
      });
      ctx.stroke();
      break;
    case 'points': case 'sphere_list': case 'cube_list':
      m.points.forEach(([x, y], i) => {
        const [px, py] = toScreen(x, y);
        const d = size(m.scale[0], 3);
        if (m.colors.length) ctx.fillStyle = css(m.colors[i]);
        if (m.type === 'sphere_list') {
          ctx.beginPath();
          ctx.arc(px, py, d / 2, 0, 2 * Math.PI);
          ctx.fill();
        } else {
          ctx.fillRect(px - d / 2, py - d / 2, d, d);
        }
      });
      break;
    case 'text':
      ctx.font = `${Math.round(Math.min(32, size(m.scale[2], 10)))}px system-ui, sans-serif`;
      ctx.textAlign = 'center';
      ctx.textBaseline = 'middle';
      ctx.fillText(m.text, sx, sy);
      ctx.textAlign = 'start';
      break;
    default:
      break;
  }
}
