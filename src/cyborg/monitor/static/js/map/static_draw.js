// The map's static layers, drawn once per view into a bitmap that the page then reuses frame
// after frame: scanned points, walls, forbidden lines and areas, simulator boxes, goals (with
// heading ticks), docks and home. Their names are not in the bitmap: they are placed with every
// other label of the frame (labels.js, moving_draw.js), so that a robot's name and a goal's
// give way to each other.
//
// Runs in the static worker (static_worker.js, on an OffscreenCanvas) or, where workers cannot
// draw, on the page itself: it uses nothing but a 2D context, so both are the same code.
//
// Why pixels for the points: columbia.map has 63,311 scanned points. One fillRect each took
// 35–130 ms in Chromium (software rendering); writing them straight into an ImageData's
// pixels (one 32-bit store each) took 11–23 ms. So the points go into a Uint32Array over the
// ImageData, which is put on the canvas first; the vector layers are stroked on top.
//
// `region` is where the bitmap lies in the world: its top-left corner (x0, y1) in metres, its
// size in CSS px (width, height), the scale in px per m and the device pixel ratio. The canvas
// is width·dpr × height·dpr device pixels, and everything here is in device pixels:
//   px = (x - x0) · scale · dpr,   py = (y1 - y) · scale · dpr

import { CATEGORY } from "./map_model.js";

const POINT_RGBA = [60, 64, 67, 255];
const WALL = "#202124";
const FORBIDDEN = "#d93025";
const FORBIDDEN_FILL = "rgba(217, 48, 37, 0.12)";
const GOAL = "#00897b";
const DOCK = "#5e35b1";
const HOME = "#188038";
const OBSTACLE = "rgba(128, 134, 139, 0.55)";
const LITTLE_ENDIAN = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

// Draws the layers switched on in `layers` ({points, walls, forbidden, goals}) and
// returns what it drew: {points, lines, objects} counts and the time taken (ms).
export function drawStatic(ctx, data, region, layers) {
  const started = performance.now();
  const canvas = ctx.canvas;
  const k = region.scale * region.dpr;
  const place = { x0: region.x0, y1: region.y1, k, w: canvas.width, h: canvas.height, dpr: region.dpr };
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  const drawn = { points: 0, lines: 0, objects: 0 };
  if (layers.points && data.points.length) drawn.points = drawPoints(ctx, data.points, data.resolution, place);
  if (layers.walls && data.lines.length) drawn.lines = drawWalls(ctx, data.lines, place);
  drawn.objects = drawObjects(ctx, data.objects, place, layers);
  return { ...drawn, ms: performance.now() - started };
}

// One 32-bit store per point (a 2×2 stamp once the points are 3 device pixels apart or more).
function drawPoints(ctx, points, resolution, place) {
  const { x0, y1, k, w, h } = place;
  const image = ctx.createImageData(w, h);
  const pixels = new Uint32Array(image.data.buffer);
  const [r, g, b, a] = POINT_RGBA;
  const colour = LITTLE_ENDIAN ? ((a << 24) | (b << 16) | (g << 8) | r) >>> 0 : ((r << 24) | (g << 16) | (b << 8) | a) >>> 0;
  const stamp = (resolution || 0.02) * k >= 3 ? 2 : 1;
  let count = 0;
  for (let i = 0; i < points.length; i += 2) {
    // `| 0` truncates to an int; the comparisons also drop NaN.
    const px = ((points[i] - x0) * k) | 0;
    const py = ((y1 - points[i + 1]) * k) | 0;
    if (px < 0 || py < 0 || px >= w || py >= h) continue;
    const at = py * w + px;
    pixels[at] = colour;
    if (stamp === 2) {
      if (px + 1 < w) pixels[at + 1] = colour;
      if (py + 1 < h) {
        pixels[at + w] = colour;
        if (px + 1 < w) pixels[at + w + 1] = colour;
      }
    }
    count += 1;
  }
  ctx.putImageData(image, 0, 0);
  return count;
}

// One path for all the walls inside the region (a wall crossing its edge counts).
function drawWalls(ctx, lines, place) {
  const { x0, y1, k, w, h, dpr } = place;
  ctx.beginPath();
  let count = 0;
  for (let i = 0; i < lines.length; i += 4) {
    const ax = (lines[i] - x0) * k, ay = (y1 - lines[i + 1]) * k;
    const bx = (lines[i + 2] - x0) * k, by = (y1 - lines[i + 3]) * k;
    if (Math.max(ax, bx) < 0 || Math.min(ax, bx) > w || Math.max(ay, by) < 0 || Math.min(ay, by) > h) continue;
    ctx.moveTo(ax, ay);
    ctx.lineTo(bx, by);
    count += 1;
  }
  // about 5 cm thick, but never thinner than a pixel or wider than three
  ctx.lineWidth = Math.min(3 * dpr, Math.max(dpr, 0.05 * k));
  ctx.lineCap = "round";
  ctx.strokeStyle = WALL;
  ctx.stroke();
  return count;
}

// The layer that draws objects of `category` (and shows their names): "forbidden", "walls"
// (simulator boxes, other shapes) or "goals" (goals, docks, home).
export function layerOf(category) {
  if (category === CATEGORY.FORBIDDEN_AREA || category === CATEGORY.FORBIDDEN_LINE) return "forbidden";
  if (category === CATEGORY.SIM_OBSTACLE || category === CATEGORY.OTHER) return "walls";
  return "goals";
}

function drawObjects(ctx, objects, place, layers) {
  const { x0, y1, k, w, h, dpr } = place;
  const at = (x, y) => [(x - x0) * k, (y1 - y) * k];
  const margin = 60 * dpr; // a marker near the edge still shows
  const inside = ([px, py]) => px > -margin && py > -margin && px < w + margin && py < h + margin;
  let count = 0;
  // areas first, then lines, then markers
  const order = [CATEGORY.SIM_OBSTACLE, CATEGORY.FORBIDDEN_AREA, CATEGORY.OTHER, CATEGORY.FORBIDDEN_LINE, CATEGORY.HOME, CATEGORY.DOCK, CATEGORY.GOAL, CATEGORY.GOAL_WITH_HEADING];
  for (const category of order) {
    if (!layers[layerOf(category)]) continue;
    for (const item of objects) {
      if (item.category !== category) continue;
      const corners = [];
      for (let i = 0; i < item.outline.length; i += 2) corners.push(at(item.outline[i], item.outline[i + 1]));
      const centre = at(item.x, item.y);
      if (!(corners.length ? corners.some(inside) || crosses(corners, w, h) : inside(centre))) continue;
      count += 1;
      ctx.setLineDash([]);
      if (corners.length >= 2) outline(ctx, corners, category, dpr);
      else marker(ctx, item, centre, dpr);
    }
  }
  return count;
}

// Whether a polygon's bounding box overlaps the canvas (a big area around the view).
function crosses(corners, w, h) {
  const xs = corners.map((c) => c[0]), ys = corners.map((c) => c[1]);
  return Math.max(...xs) >= 0 && Math.min(...xs) <= w && Math.max(...ys) >= 0 && Math.min(...ys) <= h;
}

function outline(ctx, corners, category, dpr) {
  ctx.beginPath();
  ctx.moveTo(corners[0][0], corners[0][1]);
  for (const [px, py] of corners.slice(1)) ctx.lineTo(px, py);
  const area = corners.length > 2;
  if (area) ctx.closePath();
  if (category === CATEGORY.FORBIDDEN_AREA || category === CATEGORY.FORBIDDEN_LINE) {
    if (area) {
      ctx.fillStyle = FORBIDDEN_FILL;
      ctx.fill();
    }
    ctx.strokeStyle = FORBIDDEN;
    ctx.lineWidth = (area ? 1.5 : 2.5) * dpr;
    if (!area) ctx.setLineDash([6 * dpr, 3 * dpr]);
  } else if (category === CATEGORY.SIM_OBSTACLE) {
    ctx.fillStyle = OBSTACLE;
    ctx.fill();
    ctx.strokeStyle = "#5f6368";
    ctx.lineWidth = dpr;
  } else if (category === CATEGORY.HOME) {
    ctx.strokeStyle = HOME;
    ctx.lineWidth = 1.5 * dpr;
    ctx.setLineDash([4 * dpr, 3 * dpr]);
  } else {
    ctx.strokeStyle = "#9aa0a6";
    ctx.lineWidth = dpr;
    ctx.setLineDash([2 * dpr, 3 * dpr]);
  }
  ctx.stroke();
  ctx.setLineDash([]);
}

// A goal is a teal dot, a dock a purple square, home a green house; goals with a heading and
// docks get a tick pointing where the robot will face (y flips on screen).
function marker(ctx, item, [px, py], dpr) {
  ctx.lineWidth = 1.5 * dpr;
  ctx.strokeStyle = "#ffffff";
  ctx.beginPath();
  if (item.category === CATEGORY.DOCK) {
    ctx.rect(px - 5 * dpr, py - 5 * dpr, 10 * dpr, 10 * dpr);
    ctx.fillStyle = DOCK;
  } else if (item.category === CATEGORY.HOME) {
    const s = 6 * dpr;
    ctx.moveTo(px, py - 1.4 * s);
    ctx.lineTo(px + s, py - 0.3 * s);
    ctx.lineTo(px + s, py + s);
    ctx.lineTo(px - s, py + s);
    ctx.lineTo(px - s, py - 0.3 * s);
    ctx.closePath();
    ctx.fillStyle = HOME;
  } else {
    ctx.arc(px, py, 5 * dpr, 0, 2 * Math.PI);
    ctx.fillStyle = GOAL;
  }
  ctx.fill();
  ctx.stroke();
  if (item.category === CATEGORY.GOAL_WITH_HEADING || item.category === CATEGORY.DOCK) {
    const reach = 15 * dpr;
    ctx.beginPath();
    ctx.moveTo(px, py);
    ctx.lineTo(px + reach * Math.cos(item.th), py - reach * Math.sin(item.th));
    ctx.strokeStyle = item.category === CATEGORY.DOCK ? DOCK : GOAL;
    ctx.lineWidth = 2 * dpr;
    ctx.stroke();
  }
}
