// World (map frame, metres) <-> floorplan image pixels <-> canvas (CSS) pixels. Pure, so the
// formulas can be checked without a browser. World <-> pixel is rover_web/map_geometry.py's,
// map_server's conventions, so the page and the server agree to the pixel; pixel <-> screen is
// the whole view: screen = offset + pixel * scale.

// A press that moves less than this is a click, not a drag.
export const CLICK_SLOP_PX = 5;

// g: { w, h, res, ox, oy, oyaw }, the same for a floorplan file and a live OccupancyGrid.
export function geometryOf(params) {
  const { png, yaml } = params.files;
  const [ox, oy, oyaw = 0] = yaml.origin;
  return { w: png.pixel_width, h: png.pixel_height, res: yaml.resolution, ox, oy, oyaw };
}

export function geometryOfLiveMap(m) {
  const [ox, oy, oyaw = 0] = m.origin;
  return { w: m.width_px, h: m.height_px, res: m.resolution_m, ox, oy, oyaw };
}

export function worldToPixel(g, x, y) {
  let dx = x - g.ox;
  let dy = y - g.oy;
  if (g.oyaw) {
    const c = Math.cos(g.oyaw), s = Math.sin(g.oyaw);
    [dx, dy] = [c * dx + s * dy, -s * dx + c * dy];
  }
  return [dx / g.res, g.h - dy / g.res];
}

export function pixelToWorld(g, px, py) {
  let u = px * g.res;
  let v = (g.h - py) * g.res;
  if (g.oyaw) {
    const c = Math.cos(g.oyaw), s = Math.sin(g.oyaw);
    [u, v] = [c * u - s * v, s * u + c * v];
  }
  return [g.ox + u, g.oy + v];
}

export function insideMap(g, x, y) {
  const [px, py] = worldToPixel(g, x, y);
  return px >= 0 && px <= g.w && py >= 0 && py <= g.h;
}

// view: { scale, ox, oy }
export const pixelToScreen = (view, px, py) => [view.ox + px * view.scale, view.oy + py * view.scale];
export const screenToPixel = (view, sx, sy) => [(sx - view.ox) / view.scale, (sy - view.oy) / view.scale];
export const worldToScreen = (g, view, x, y) => pixelToScreen(view, ...worldToPixel(g, x, y));
export const screenToWorld = (g, view, sx, sy) => pixelToWorld(g, ...screenToPixel(view, sx, sy));

export const isDrag = (sx, sy, ex, ey) => Math.hypot(ex - sx, ey - sy) >= CLICK_SLOP_PX;

// Screen y points down while map angles count up, and the image is turned by the origin's yaw.
export const screenAngle = (sx, sy, ex, ey) => Math.atan2(sy - ey, ex - sx);
export const mapYawOfScreen = (g, angle) => angle + g.oyaw;
export const screenOfMapYaw = (g, yaw) => yaw - g.oyaw;

export const wrapAngle = (angle) => Math.atan2(Math.sin(angle), Math.cos(angle));

// The heading of a goal given by pressing at (sx, sy) and releasing at (ex, ey) over world point
// (x, y): a drag points the way it was dragged; a plain click faces the way from the robot, when
// its pose is live (pose null otherwise), to the point.
export function gestureYaw(g, sx, sy, ex, ey, x, y, pose) {
  let yaw = 0;
  if (isDrag(sx, sy, ex, ey)) yaw = mapYawOfScreen(g, screenAngle(sx, sy, ex, ey));
  else if (pose) yaw = Math.atan2(y - pose.y, x - pose.x);
  return wrapAngle(yaw);
}
