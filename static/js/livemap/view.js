// Pan and zoom. The pure functions compute a view ({ scale, ox, oy }) from a view, a geometry and
// the canvas size ({ width, height }, CSS pixels); createViewport holds the page's view in its
// model and asks for a redraw whenever it changes.
import { screenToPixel, worldToScreen } from './geometry.js';

export function fitScale(g, size) {
  return Math.max(1e-3, 0.96 * Math.min(size.width / g.w, size.height / g.h));
}

// Out to an eighth of the fitted map; in far enough to see single cells, however small the map.
export function clampScale(g, size, scale) {
  const fit = fitScale(g, size);
  return Math.min(Math.max(scale, fit / 8), Math.max(fit * 64, 40));
}

export function fitView(g, size) {
  const scale = fitScale(g, size);
  return { scale, ox: (size.width - g.w * scale) / 2, oy: (size.height - g.h * scale) / 2 };
}

// The view at `scale` that shows image pixel (px, py) at screen point (sx, sy).
export const viewWithPixelAt = (scale, px, py, sx, sy) => ({ scale, ox: sx - px * scale, oy: sy - py * scale });

// Zooming about a point keeps the floorplan under that point where it is.
export function zoomView(g, size, view, factor, sx, sy) {
  return viewWithPixelAt(clampScale(g, size, view.scale * factor), ...screenToPixel(view, sx, sy), sx, sy);
}

export const panView = (view, dx, dy) => ({ scale: view.scale, ox: view.ox + dx, oy: view.oy + dy });

// A resized canvas keeps what was in its middle in its middle.
export const resizeView = (view, from, to) => panView(view, (to.width - from.width) / 2, (to.height - from.height) / 2);

// model: { geometry, view, size, fitted, tracking, pose }.
export function createViewport(model, redraw) {
  const set = (view) => { model.view = view; redraw(); };
  const centre = () => [model.size.width / 2, model.size.height / 2];
  const robotOnScreen = () => worldToScreen(model.geometry, model.view, model.pose.x, model.pose.y);
  const viewport = {
    fit() {
      model.fitted = true;
      set(fitView(model.geometry, model.size));
    },
    zoomAt(factor, sx, sy) { set(zoomView(model.geometry, model.size, model.view, factor, sx, sy)); },
    panBy(dx, dy) { set(panView(model.view, dx, dy)); },
    // scale is clamped like any zoom; a pinch keeps `pixel` under the fingers' midpoint.
    showPixelAt(scale, [px, py], sx, sy) {
      set(viewWithPixelAt(clampScale(model.geometry, model.size, scale), px, py, sx, sy));
    },
    centreOnRobot() {
      if (!model.pose) return;
      const [sx, sy] = robotOnScreen();
      const [cx, cy] = centre();
      viewport.panBy(cx - sx, cy - sy);
    },
    // Toolbar and key zooms: about the middle, or about the robot while tracking it.
    zoomCentre(factor) {
      if (model.tracking && model.pose) {
        viewport.zoomAt(factor, ...robotOnScreen());
        viewport.centreOnRobot();
      } else {
        viewport.zoomAt(factor, ...centre());
      }
    },
    resize(width, height) {
      const to = { width, height };
      if (model.fitted) model.view = resizeView(model.view, model.size, to);
      model.size = to;
      if (!model.fitted) viewport.fit();
      if (model.tracking) viewport.centreOnRobot();
    },
  };
  return viewport;
}
