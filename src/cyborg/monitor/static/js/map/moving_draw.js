// One frame of the map. Called from requestAnimationFrame only when something changed (a
// robot's message, the view, a new bitmap), never in an idle loop.
//
// Two canvases, one over the other. The lower one holds the static bitmap, blitted (shifted
// and scaled to the current view while a new one is drawn) only when the view or the bitmap
// changed: a robot moving does not repaint the map under it. The upper one is cleared and
// drawn every frame: planned paths (the part already travelled faded), the current goal,
// laser hits, tracked objects (tracked_draw.js), detected objects, robots (footprint in the
// robot's colour, heading as a white arrow), then names.
// A robot that left the bus (the monitor's map_robots says it is not alive) is drawn faded,
// without its laser, where it was last seen.
//
// Everything here is in CSS pixels: the context is scaled by the device pixel ratio once.

import { drawTracked } from "./tracked_draw.js";
import { trackedNow } from "./tracked_objects.js";

const MIN_ROBOT_PX = 14; // a robot is never drawn smaller than this, however far out
const DOT_PX = 2;
const GONE_ALPHA = 0.35;
const DIAMOND_PX = 6;

// The lower canvas: the static bitmap at `placement` (StaticLayer.placement()), or nothing.
export function drawBitmap(ctx, view, placement, dpr) {
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, view.width, view.height);
  if (placement) blit(ctx, placement, dpr);
}

// The upper canvas. `scene`: {view (ViewTransform), dpr, model (MapModel), robots (the robots
// to draw, [robot]), layers, selected (ns or null)}. Returns what it drew: {robots, laser,
// paths, goals, tracked, arrows, trackedLabels, detections, names}.
export function drawMoving(ctx, scene) {
  const { view, dpr, layers } = scene;
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, view.width, view.height);
  const drawn = { robots: 0, laser: 0, paths: 0, goals: 0, tracked: 0, arrows: 0, trackedLabels: 0, detections: 0, names: 0 };
  if (layers.paths) {
    for (const robot of scene.robots) {
      if (scene.model.pathShown(robot)) drawn.paths += drawPath(ctx, view, robot);
    }
  }
  for (const robot of scene.robots) {
    if (robot.goal && scene.model.travelling(robot)) drawn.goals += drawGoal(ctx, view, robot, layers.labels);
  }
  if (layers.laser) {
    for (const robot of scene.robots) if (robot.alive) drawn.laser += drawScan(ctx, view, robot);
  }
  if (layers.tracked) {
    const placed = layers.labels ? [] : null; // label boxes, shared so robots' labels do not collide
    for (const robot of scene.robots) {
      if (!robot.alive) continue;
      const { objects, arrows, labels } = drawTracked(ctx, view, robot, trackedNow(robot), placed);
      drawn.tracked += objects;
      drawn.arrows += arrows;
      drawn.trackedLabels += labels;
    }
  }
  if (layers.detections) {
    for (const robot of scene.robots) {
      if (robot.alive) drawn.detections += drawDetections(ctx, view, robot, scene.model.seenNow(robot), layers.labels);
    }
  }
  if (layers.robots) {
    for (const robot of scene.robots) {
      if (!robot.pose) continue;
      ctx.globalAlpha = robot.alive ? 1 : GONE_ALPHA;
      drawRobot(ctx, view, robot, robot.ns === scene.selected && scene.robots.length > 1);
      ctx.globalAlpha = 1;
      drawn.robots += 1;
    }
    if (layers.labels) {
      for (const robot of scene.robots) {
        if (robot.pose) {
          drawName(ctx, view, robot);
          drawn.names += 1;
        }
      }
    }
  }
  return drawn;
}

function blit(ctx, { bitmap, x, y, w, h }, dpr) {
  const sameScale = Math.abs(w * dpr - bitmap.width) < 0.5;
  if (sameScale) {
    // At the scale it was drawn, on whole device pixels: crisp, no resampling.
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(bitmap, Math.round(x * dpr) / dpr, Math.round(y * dpr) / dpr, bitmap.width / dpr, bitmap.height / dpr);
  } else {
    ctx.imageSmoothingEnabled = true;
    ctx.drawImage(bitmap, x, y, w, h);
  }
}

function drawPath(ctx, view, robot) {
  const { xy } = robot.path;
  const n = xy.length / 2;
  if (n < 2) return 0;
  const progress = robot.progress;
  const split = progress ? progress.index : 0;
  ctx.lineJoin = "round";
  ctx.lineCap = "round";
  // travelled: vertices 0..split, then the robot's foot on the path
  if (progress) {
    ctx.beginPath();
    for (let i = 0; i <= split; i++) lineTo(ctx, view, xy[2 * i], xy[2 * i + 1], i === 0);
    lineTo(ctx, view, progress.x, progress.y, false);
    ctx.globalAlpha = 0.25;
    ctx.strokeStyle = robot.colour;
    ctx.lineWidth = 3;
    ctx.stroke();
    ctx.globalAlpha = 1;
  }
  ctx.beginPath();
  if (progress) lineTo(ctx, view, progress.x, progress.y, true);
  for (let i = progress ? split + 1 : 0; i < n; i++) lineTo(ctx, view, xy[2 * i], xy[2 * i + 1], !progress && i === 0);
  ctx.strokeStyle = robot.colour;
  ctx.lineWidth = 2.5;
  ctx.stroke();
  return n;
}

function lineTo(ctx, view, x, y, first) {
  const [sx, sy] = view.toScreen(x, y);
  if (first) ctx.moveTo(sx, sy);
  else ctx.lineTo(sx, sy);
}

// The goal the robot is on its way to: a ring in its colour, a tick for its heading (when the
// robot turns to it there), and its name when labels are on.
function drawGoal(ctx, view, robot, labels) {
  const goal = robot.goal;
  const [sx, sy] = view.toScreen(goal.x, goal.y);
  ctx.beginPath();
  ctx.arc(sx, sy, 10, 0, 2 * Math.PI);
  ctx.strokeStyle = robot.colour;
  ctx.lineWidth = 3;
  ctx.stroke();
  if (goal.heading) {
    ctx.beginPath();
    ctx.moveTo(sx, sy);
    ctx.lineTo(sx + 18 * Math.cos(goal.th), sy - 18 * Math.sin(goal.th));
    ctx.lineWidth = 2;
    ctx.stroke();
  }
  if (labels && goal.name) {
    const name = goal.name.length > 40 ? `${goal.name.slice(0, 39)}…` : goal.name;
    ctx.font = 'bold 11px system-ui, "DejaVu Sans", sans-serif';
    ctx.textBaseline = "top";
    ctx.textAlign = "center";
    ctx.lineJoin = "round";
    ctx.lineWidth = 3;
    ctx.strokeStyle = "rgba(255, 255, 255, 0.92)";
    ctx.strokeText(name, sx, sy + 13);
    ctx.fillStyle = robot.colour;
    ctx.fillText(name, sx, sy + 13);
    ctx.textAlign = "left";
  }
  return 1;
}

// Laser hits as 2 px squares in the robot's colour (those off screen are skipped), as one
// path: one fill per robot rasterises cheaper than a fillRect per hit.
function drawScan(ctx, view, robot) {
  if (!robot.scan || !robot.scanCount) return 0;
  const { scan, scanCount } = robot;
  const { width, height, scale, cx, cy } = view;
  const ox = width / 2 - cx * scale, oy = height / 2 + cy * scale;
  ctx.fillStyle = robot.colour;
  ctx.globalAlpha = 0.85;
  ctx.beginPath();
  let count = 0;
  for (let i = 0; i < scanCount; i++) {
    const sx = ox + scan[2 * i] * scale, sy = oy - scan[2 * i + 1] * scale;
    if (sx < -DOT_PX || sy < -DOT_PX || sx > width || sy > height) continue;
    ctx.rect(sx - DOT_PX / 2, sy - DOT_PX / 2, DOT_PX, DOT_PX);
    count += 1;
  }
  ctx.fill();
  ctx.globalAlpha = 1;
  return count;
}

// The objects the robot's detector saw: a diamond outlined in the robot's colour on white,
// with the class and score beside it when labels are on.
function drawDetections(ctx, view, robot, items, labels) {
  let count = 0;
  ctx.font = '11px system-ui, "DejaVu Sans", sans-serif';
  ctx.textBaseline = "middle";
  ctx.textAlign = "left";
  ctx.lineJoin = "round";
  for (const item of items) {
    const [sx, sy] = view.toScreen(item.x, item.y);
    if (sx < -DIAMOND_PX || sy < -DIAMOND_PX || sx > view.width + DIAMOND_PX || sy > view.height + DIAMOND_PX) continue;
    ctx.beginPath();
    ctx.moveTo(sx, sy - DIAMOND_PX);
    ctx.lineTo(sx + DIAMOND_PX, sy);
    ctx.lineTo(sx, sy + DIAMOND_PX);
    ctx.lineTo(sx - DIAMOND_PX, sy);
    ctx.closePath();
    ctx.fillStyle = "#ffffff";
    ctx.fill();
    ctx.strokeStyle = robot.colour;
    ctx.lineWidth = 2.5;
    ctx.stroke();
    if (labels && item.label) {
      const text = item.score === null ? item.label : `${item.label} ${Math.round(item.score * 100)} %`;
      ctx.lineWidth = 3;
      ctx.strokeStyle = "rgba(255, 255, 255, 0.92)";
      ctx.strokeText(text, sx + DIAMOND_PX + 3, sy);
      ctx.fillStyle = "#3c4043";
      ctx.fillText(text, sx + DIAMOND_PX + 3, sy);
    }
    count += 1;
  }
  return count;
}

// The footprint, in the robot's colour, at least MIN_ROBOT_PX across; the heading as a white
// arrow in its front half (the centre pixel keeps the robot's colour).
function drawRobot(ctx, view, robot, selected) {
  const { x, y, th } = robot.pose;
  const [sx, sy] = view.toScreen(x, y);
  const fp = robot.footprint;
  let reach = 0;
  for (let i = 0; i < fp.length; i += 2) reach = Math.max(reach, Math.hypot(fp[i], fp[i + 1]));
  const k = Math.max(view.scale, MIN_ROBOT_PX / 2 / Math.max(reach, 0.05)); // px per m, enlarged far out
  const cos = Math.cos(th), sin = Math.sin(th);
  const toPx = (fx, fy) => [sx + (fx * cos - fy * sin) * k, sy - (fx * sin + fy * cos) * k];
  ctx.beginPath();
  for (let i = 0; i < fp.length; i += 2) {
    const [px, py] = toPx(fp[i], fp[i + 1]);
    if (i === 0) ctx.moveTo(px, py);
    else ctx.lineTo(px, py);
  }
  ctx.closePath();
  ctx.fillStyle = robot.colour;
  ctx.fill();
  ctx.strokeStyle = selected ? "#202124" : "#ffffff";
  ctx.lineWidth = selected ? 2.5 : 1.5;
  ctx.stroke();
  const tip = toPx(reach * 0.85, 0), left = toPx(reach * 0.3, reach * 0.3), right = toPx(reach * 0.3, -reach * 0.3);
  ctx.beginPath();
  ctx.moveTo(tip[0], tip[1]);
  ctx.lineTo(left[0], left[1]);
  ctx.lineTo(right[0], right[1]);
  ctx.closePath();
  ctx.fillStyle = "#ffffff";
  ctx.fill();
}

// The robot's name with its battery (⚡ while charging, the dock state unless undocked), and
// what it is doing (the running node) under it.
function drawName(ctx, view, robot) {
  const [sx, sy] = view.toScreen(robot.pose.x, robot.pose.y);
  const lines = [robot.ns + batteryText(robot.battery) + (robot.alive ? "" : " (offline)")];
  if (robot.node) lines.push(robot.node.length > 40 ? `${robot.node.slice(0, 39)}…` : robot.node);
  const fonts = ['bold 12px system-ui, "DejaVu Sans", sans-serif', '11px system-ui, "DejaVu Sans", sans-serif'];
  // right of the robot, or left of it where the right edge would cut the text
  const widest = Math.max(...lines.map((text, i) => { ctx.font = fonts[i]; return ctx.measureText(text).width; }));
  const left = sx + 14 + widest > view.width - 4 && sx - 14 - widest >= 4;
  ctx.textBaseline = "middle";
  ctx.textAlign = left ? "right" : "left";
  ctx.lineJoin = "round";
  lines.forEach((text, i) => {
    const px = left ? sx - 14 : sx + 14, py = sy - 14 + i * 14;
    ctx.font = fonts[i];
    ctx.lineWidth = 3;
    ctx.strokeStyle = "rgba(255, 255, 255, 0.92)";
    ctx.strokeText(text, px, py);
    ctx.fillStyle = i === 0 ? robot.colour : "#3c4043";
    ctx.fillText(text, px, py);
  });
  ctx.textAlign = "left";
}

function batteryText(battery) {
  if (!battery) return "";
  const charge = battery.pct === null ? "" : ` · ${Math.round(battery.pct)} %`;
  const dock = battery.dock && battery.dock !== "UNDOCKED" ? ` · ${battery.dock.toLowerCase()}` : "";
  return `${charge}${battery.charging ? " ⚡" : ""}${dock}`;
}
