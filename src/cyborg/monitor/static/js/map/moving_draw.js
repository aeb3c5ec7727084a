// One frame of the map. Called from requestAnimationFrame only when something changed (a
// robot's message, the view, a new bitmap), never in an idle loop.
//
// Two canvases, one over the other. The lower one holds the static bitmap, blitted (shifted
// and scaled to the current view while a new one is drawn) only when the view or the bitmap
// changed: a robot moving does not repaint the map under it. The upper one is cleared and
// drawn every frame: planned paths (the part already travelled faded), the current goal,
// laser hits, tracked objects (tracked_draw.js), detected objects, robots (footprint in the
// robot's colour, heading as a white arrow), then every label on top: robots' names, objects',
// docks', goals' and areas' (the map's names too, which the bitmap leaves out), placed so that
// none covers another (labels.js).
// A robot that left the bus (the monitor's map_robots says it is not alive) is drawn faded,
// without its laser, where it was last seen.
//
// Everything here is in CSS pixels: the context is scaled by the device pixel ratio once.

import { CATEGORY } from "./map_model.js";
import { drawLabels, LabelLayout } from "./labels.js";
import { layerOf } from "./static_draw.js";
import { addLabels, drawTracked } from "./tracked_draw.js";
import { trackedNow } from "./tracked_objects.js";

const MIN_ROBOT_PX = 14; // a robot is never drawn smaller than this, however far out
const DOT_PX = 2;
const GONE_ALPHA = 0.35;
const DIAMOND_PX = 6;
const GOAL_RING_PX = 10;
const MAP_MARKER_PX = 6; // a goal's dot, a dock's square (static_draw.js), with their outline
const NAME_GAP_PX = 14; // from a robot's centre to its name, at least
const FONT = '11px system-ui, "DejaVu Sans", sans-serif';
const BOLD = 'bold 11px system-ui, "DejaVu Sans", sans-serif';
const ROBOT_FONT = 'bold 12px system-ui, "DejaVu Sans", sans-serif';
const TEXT = "#3c4043";
const MAP_TEXT = "#202124";
const LABEL_KINDS = { [CATEGORY.DOCK]: "dock", [CATEGORY.HOME]: "home", [CATEGORY.GOAL]: "goal", [CATEGORY.GOAL_WITH_HEADING]: "goal" };

// The lower canvas: the static bitmap at `placement` (StaticLayer.placement()), or nothing.
export function drawBitmap(ctx, view, placement, dpr) {
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, view.width, view.height);
  if (placement) blit(ctx, placement, dpr);
}

// The upper canvas. `scene`: {view (ViewTransform), dpr, model (MapModel), map (the shown map,
// or null), robots (the robots to draw, [robot]), layers, selected (ns or null), covered (the
// boxes the map's controls cover, which labels keep off)}. Returns
// {drawn, labels}: what it drew ({robots, laser, paths, goals, tracked, arrows, trackedLabels,
// detections, names}) and the labels placed (labels.js's, for labelBoxes).
export function drawMoving(ctx, scene) {
  const { view, dpr, layers } = scene;
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, view.width, view.height);
  const drawn = { robots: 0, laser: 0, paths: 0, goals: 0, tracked: 0, arrows: 0, trackedLabels: 0, detections: 0, names: 0 };
  const layout = layers.labels ? new LabelLayout(view.width, view.height, scene.covered) : null;
  if (layers.paths) {
    for (const robot of scene.robots) {
      if (scene.model.pathShown(robot)) drawn.paths += drawPath(ctx, view, robot);
    }
  }
  const driving = []; // the goals robots drive to: each named once, by the first robot's ring
  for (const robot of scene.robots) {
    if (robot.goal && scene.model.travelling(robot)) {
      drawn.goals += drawGoal(ctx, view, robot, driving.some((goal) => sameGoal(goal, robot.goal)) ? null : layout);
      driving.push(robot.goal);
    }
  }
  if (layout && scene.map) addMapLabels(layout, view, scene.map, layers, driving);
  if (layers.laser) {
    for (const robot of scene.robots) if (robot.alive) drawn.laser += drawScan(ctx, view, robot);
  }
  if (layers.tracked) {
    const labels = [];
    for (const robot of scene.robots) {
      if (!robot.alive) continue;
      const tracked = drawTracked(ctx, view, robot, trackedNow(robot), layout);
      drawn.tracked += tracked.objects;
      drawn.arrows += tracked.arrows;
      labels.push(...tracked.labels);
    }
    if (layout) addLabels(layout, labels);
  }
  if (layers.detections) {
    for (const robot of scene.robots) {
      if (robot.alive) drawn.detections += drawDetections(ctx, view, robot, scene.model.seenNow(robot), layout);
    }
  }
  if (layers.robots) {
    for (const robot of scene.robots) {
      if (!robot.pose) continue;
      ctx.globalAlpha = robot.alive ? 1 : GONE_ALPHA;
      const reach = drawRobot(ctx, view, robot, robot.ns === scene.selected && scene.robots.length > 1);
      ctx.globalAlpha = 1;
      drawn.robots += 1;
      if (layout) addName(layout, view, robot, reach, robot.ns === scene.selected);
    }
  }
  const placed = layout ? layout.place(ctx) : [];
  drawLabels(ctx, placed);
  for (const label of placed) {
    if (label.kind === "robot") drawn.names += 1;
    else if (label.kind === "tracked") drawn.trackedLabels += 1;
  }
  return { drawn, labels: placed };
}

// The names of the map's goals, docks, home and named areas in the view (of the layers shown),
// and their markers for the labels to keep off. A goal a robot drives to is named by its ring
// (drawGoal) instead. `driving`: those goals ({name, x, y}).
function addMapLabels(layout, view, map, layers, driving) {
  for (const item of map.objects) {
    if (!layers[layerOf(item.category)]) continue;
    const outline = item.outline;
    const [sx, sy] = outline.length >= 4 ? view.toScreen(outline[0], outline[1]) : view.toScreen(item.x, item.y);
    if (sx < 0 || sy < 0 || sx > view.width || sy > view.height) continue;
    const point = outline.length < 4;
    const own = point ? layout.marker(sx, sy, MAP_MARKER_PX) : -1;
    if (!item.name || driving.some((goal) => sameGoal(goal, item))) continue;
    layout.add({
      kind: point ? LABEL_KINDS[item.category] ?? "area" : "area", at: [sx, sy], own,
      gap: point ? MAP_MARKER_PX + 2 : 2, sides: point ? ["E"] : ["SE", "E"],
      lines: [{ text: cut(item.name), font: FONT, colour: MAP_TEXT }],
    });
  }
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

// Whether two goals ({name, x, y}) are the same: the same name, half a metre apart at most.
function sameGoal(a, b) {
  return a.name === b.name && Math.hypot(a.x - b.x, a.y - b.y) < 0.5;
}

// The goal the robot is on its way to: a ring in its colour, a tick for its heading (when the
// robot turns to it there), and its name under it when labels are on (`layout`; null for a
// goal another robot's ring names already).
function drawGoal(ctx, view, robot, layout) {
  const goal = robot.goal;
  const [sx, sy] = view.toScreen(goal.x, goal.y);
  ctx.beginPath();
  ctx.arc(sx, sy, GOAL_RING_PX, 0, 2 * Math.PI);
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
  if (layout) {
    const own = layout.marker(sx, sy, GOAL_RING_PX + 1);
    if (goal.name) {
      layout.add({
        kind: "goal", rank: -1, at: [sx, sy], own, gap: GOAL_RING_PX + 3, sides: ["S", "N"],
        lines: [{ text: cut(goal.name), font: BOLD, colour: robot.colour }],
      });
    }
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
// with the class and score beside it when labels are on (`layout`).
function drawDetections(ctx, view, robot, items, layout) {
  let count = 0;
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
    if (layout) {
      const own = layout.marker(sx, sy, DIAMOND_PX);
      if (item.label) {
        const text = item.score === null ? item.label : `${item.label} ${Math.round(item.score * 100)} %`;
        layout.add({
          kind: "detection", rank: -(item.score ?? 0), at: [sx, sy], own, gap: DIAMOND_PX + 3, sides: ["E"],
          lines: [{ text, font: FONT, colour: TEXT }],
        });
      }
    }
    count += 1;
  }
  return count;
}

// The footprint, in the robot's colour, at least MIN_ROBOT_PX across; the heading as a white
// arrow in its front half (the centre pixel keeps the robot's colour). Returns how far the
// footprint reaches from the centre, px.
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
  return reach * k;
}

// The robot's name with its battery (⚡ while charging, the dock state unless undocked), and
// what it is doing (the running node) under it: beside the robot, whose footprint reaches
// `reach` px; the selected robot's name is placed first.
function addName(layout, view, robot, reach, selected) {
  const at = view.toScreen(robot.pose.x, robot.pose.y);
  const own = layout.marker(at[0], at[1], reach);
  const name = cut(robot.ns, 32) + batteryText(robot.battery) + (robot.alive ? "" : " (offline)");
  const lines = [{ text: name, font: ROBOT_FONT, colour: robot.colour }];
  if (robot.node) lines.push({ text: cut(robot.node), font: FONT, colour: TEXT });
  layout.add({ kind: "robot", rank: selected ? 0 : 1, at, own, gap: Math.max(NAME_GAP_PX, reach + 4), sides: ["E", "W"], lines });
}

// `text` cut to `most` characters (the last an ellipsis), so that a label fits a phone.
function cut(text, most = 40) {
  return text.length > most ? `${text.slice(0, most - 1)}…` : text;
}

function batteryText(battery) {
  if (!battery) return "";
  const charge = battery.pct === null ? "" : ` · ${Math.round(battery.pct)} %`;
  const dock = battery.dock && battery.dock !== "UNDOCKED" ? ` · ${battery.dock.toLowerCase()}` : "";
  return `${charge}${battery.charging ? " ⚡" : ""}${dock}`;
}
