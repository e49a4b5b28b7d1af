// The route being made (dashed, numbered) and the running Nav2 goal's poses (numbered, the current
// waypoint ringed) over LiveMap's canvas, after the rest of the scene is drawn.
const ROUTE = '#d2a8ff';
const GOAL = '#f0883e';
const DONE = new Set(['succeeded', 'canceled', 'aborted', 'unknown']);

function numbered(ctx, points, toScreen, color, current, dashed) {
  if (!points.length) return [];
  ctx.save();
  ctx.strokeStyle = color;
  ctx.lineWidth = 2;
  if (dashed) ctx.setLineDash([6, 5]);
  ctx.beginPath();
  points.forEach((p, i) => {
    const [sx, sy] = toScreen(p.x, p.y);
    if (i) ctx.lineTo(sx, sy); else ctx.moveTo(sx, sy);
  });
  if (points.length > 1) ctx.stroke();
  ctx.setLineDash([]);
  ctx.font = 'bold 11px system-ui, sans-serif';
  ctx.textAlign = 'center';
  ctx.textBaseline = 'middle';
  const drawn = points.map((p, i) => {
    const [sx, sy] = toScreen(p.x, p.y);
    ctx.fillStyle = color;
    ctx.beginPath();
    ctx.arc(sx, sy, 8, 0, 2 * Math.PI);
    ctx.fill();
    if (i === current) {
      ctx.beginPath();
      ctx.arc(sx, sy, 13, 0, 2 * Math.PI);
      ctx.stroke();
    }
    ctx.fillStyle = '#111';
    ctx.fillText(String(i + 1), sx, sy);
    return { x: p.x, y: p.y, screen: { x: sx, y: sy } };
  });
  ctx.restore();
  return drawn;
}

// What was drawn, for window.liveMapState.nav2.
export function drawNav2(ctx, toScreen, S) {
  const out = { route: numbered(ctx, S.route || [], toScreen, ROUTE, -1, true), goal: [] };
  const n = S.nav2;
  if (n && n.goal && n.goal.poses.length > 1 && !DONE.has(n.goal.status)) {
    const f = n.feedback;
    let current = -1;
    if (f && n.goal.kind === 'follow_waypoints') current = f.current_waypoint;
    if (f && n.goal.kind === 'through_poses') current = n.goal.poses.length - f.number_of_poses_remaining;
    out.goal = numbered(ctx, n.goal.poses, toScreen, GOAL, current, false);
  }
  return out;
}
