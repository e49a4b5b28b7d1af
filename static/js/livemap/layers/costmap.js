// Costmaps: the server sends one byte per cell (0..100 Nav2 cost, 255 unknown), deflated and in
// base64. Each new grid is decoded once into an offscreen canvas through a colour table; every
// frame then only draws that canvas, turned and scaled onto the map, at the chosen opacity.
import { worldToScreen } from '../geometry.js';

// RViz's "costmap" colour scheme: free is clear, inflation runs blue to red, 99 (inscribed) is
// cyan, 100 (lethal) magenta; unknown a faint grey, so the floorplan still shows through.
function palette() {
  const table = new Uint8ClampedArray(256 * 4);
  for (let cost = 1; cost <= 98; cost += 1) {
    const t = (cost - 1) / 97;
    table.set([Math.round(255 * t), 0, Math.round(255 * (1 - t)), 255], cost * 4);
  }
  table.set([0, 255, 255, 255], 99 * 4);
  table.set([255, 0, 255, 255], 100 * 4);
  table.set([128, 128, 128, 60], 255 * 4);
  return table;
}
const PALETTE = palette();

async function inflate(base64) {
  const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}

// One costmap as a canvas of its cells, image row 0 at the top (the grid's last row).
export async function renderCostmap(layer) {
  const cells = await inflate(layer.data);
  const { width, height } = layer;
  if (cells.length !== width * height) throw new Error(`costmap ${layer.topic}: ${cells.length} cells for ${width}x${height}`);
  const canvas = document.createElement('canvas');
  canvas.width = width;
  canvas.height = height;
  const image = new ImageData(width, height);
  const rgba = image.data;
  for (let row = 0; row < height; row += 1) {
    const from = row * width;
    const to = (height - 1 - row) * width * 4;
    for (let col = 0; col < width; col += 1) {
      const c = cells[from + col] * 4;
      const o = to + col * 4;
      rgba[o] = PALETTE[c]; rgba[o + 1] = PALETTE[c + 1]; rgba[o + 2] = PALETTE[c + 2]; rgba[o + 3] = PALETTE[c + 3];
    }
  }
  canvas.getContext('2d').putImageData(image, 0, 0);
  return canvas;
}

// Draw the rendered grid where its cells are: the canvas's (0, 0) is the grid's top-left corner
// in the world, its x axis the grid's +x and its y axis the grid's -y, all turned by the origin yaw.
export function drawCostmap(ctx, g, view, dpr, layer, canvas, opacity) {
  const [ox, oy, oyaw = 0] = layer.origin;
  const w = layer.width * layer.resolution;
  const h = layer.height * layer.resolution;
  const c = Math.cos(oyaw), s = Math.sin(oyaw);
  const world = (u, v) => [ox + c * u - s * v, oy + s * u + c * v];
  const [x0, y0] = worldToScreen(g, view, ...world(0, h));
  const [x1, y1] = worldToScreen(g, view, ...world(w, h));
  const [x2, y2] = worldToScreen(g, view, ...world(0, 0));
  ctx.save();
  ctx.globalAlpha = opacity;
  ctx.imageSmoothingEnabled = false;
  ctx.setTransform(dpr * (x1 - x0) / layer.width, dpr * (y1 - y0) / layer.width,
    dpr * (x2 - x0) / layer.height, dpr * (y2 - y0) / layer.height, dpr * x0, dpr * y0);
  ctx.drawImage(canvas, 0, 0);
  ctx.restore();
}
