// Drawing the objects a robot's tracker follows (tracked_objects.js gives them, aged to now).
//
// Each object is a marker in the robot's colour family: filled with a light tint of the robot's
// colour and outlined in the colour itself; a person a circle, anything else a square. A
// moving object (faster than MOVING_MPS) gets an arrow along its velocity as long as one second
// of its motion (at least a little longer than the marker, so a slow one still shows which
// way). Older objects are more transparent (`alpha`). When labels are on and the map is zoomed
// in to at least LABEL_MIN_SCALE px per m, each gets its label and id (`person #4`) beside it,
// placed with the frame's other labels (labels.js: after the robots' names, before goals'),
// most confident first, across all robots, at most MAX_LABELS, so a crowd stays readable.

const MARK_PX = 7; // a person's radius, half a square's side
const MOVING_MPS = 0.1; // slower than this, no arrow
const ARROW_S = 1; // an arrow is this many seconds of motion long
const HEAD_PX = 6;
export const LABEL_MIN_SCALE = 8; // px per m: zoomed out further, no labels
const MAX_LABELS = 40;
const FONT = '11px system-ui, "DejaVu Sans", sans-serif';

// Draws `items` of `robot` (with `alpha`, see trackedNow). `layout`: the frame's LabelLayout
// (labels.js), told where each marker is; null when labels are off. Returns {objects, arrows,
// labels}: how many objects and arrows were drawn, and the labels they want (for addLabels).
export function drawTracked(ctx, view, robot, items, layout) {
  const drawn = { objects: 0, arrows: 0, labels: [] };
  const margin = MARK_PX + HEAD_PX;
  const shown = items.map((item) => ({ item, at: view.toScreen(item.x, item.y) }))
    .filter(({ at: [sx, sy] }) => sx > -margin && sy > -margin && sx < view.width + margin && sy < view.height + margin);
  const tint = tintOf(robot.colour);
  ctx.lineJoin = "round";
  ctx.lineCap = "round";
  for (const { item, at } of shown) { // arrows first: markers go over their tails
    const speed = Math.hypot(item.vx, item.vy);
    if (speed <= MOVING_MPS) continue;
    const length = Math.max(speed * ARROW_S * view.scale, MARK_PX + HEAD_PX + 4);
    ctx.globalAlpha = item.alpha;
    arrow(ctx, at, [item.vx / speed, -item.vy / speed], length, robot.colour);
    drawn.arrows += 1;
  }
  const labelled = layout && view.scale >= LABEL_MIN_SCALE;
  for (const { item, at: [sx, sy] } of shown) {
    ctx.globalAlpha = item.alpha;
    ctx.beginPath();
    if (isPerson(item.label)) ctx.arc(sx, sy, MARK_PX, 0, 2 * Math.PI);
    else ctx.rect(sx - MARK_PX + 1, sy - MARK_PX + 1, 2 * MARK_PX - 2, 2 * MARK_PX - 2);
    ctx.fillStyle = tint;
    ctx.fill();
    ctx.strokeStyle = robot.colour;
    ctx.lineWidth = 2.5;
    ctx.stroke();
    drawn.objects += 1;
    if (!layout) continue;
    const own = layout.marker(sx, sy, MARK_PX);
    if (labelled) {
      drawn.labels.push({
        kind: "tracked", at: [sx, sy], gap: MARK_PX + 3, own, alpha: item.alpha, rank: -item.conf,
        lines: [{ text: `${item.label || "object"} #${item.id}`, font: FONT, colour: "#3c4043" }],
      });
    }
  }
  ctx.globalAlpha = 1;
  return drawn;
}

// Gives `layout` the most confident MAX_LABELS of the tracked objects' `labels` (of every
// robot); returns how many it was given.
export function addLabels(layout, labels) {
  const kept = [...labels].sort((a, b) => a.rank - b.rank).slice(0, MAX_LABELS);
  for (const label of kept) layout.add(label);
  return kept.length;
}

export function isPerson(label) {
  return /^(person|people|pedestrian|human)$/i.test(label);
}

// The robot's colour halfway to white: the fill of its objects' markers.
export function tintOf(colour) {
  const rgb = [1, 3, 5].map((i) => parseInt(colour.slice(i, i + 2), 16));
  return `rgb(${rgb.map((c) => Math.round((c + 255) / 2)).join(", ")})`;
}

// An arrow from `from` along the unit screen direction `[dx, dy]`, `length` px long.
function arrow(ctx, [sx, sy], [dx, dy], length, colour) {
  const tx = sx + dx * length, ty = sy + dy * length;
  ctx.beginPath();
  ctx.moveTo(sx, sy);
  ctx.lineTo(tx - dx * HEAD_PX * 0.5, ty - dy * HEAD_PX * 0.5);
  ctx.strokeStyle = colour;
  ctx.lineWidth = 2;
  ctx.stroke();
  ctx.beginPath();
  ctx.moveTo(tx, ty);
  ctx.lineTo(tx - dx * HEAD_PX - dy * HEAD_PX * 0.6, ty - dy * HEAD_PX + dx * HEAD_PX * 0.6);
  ctx.lineTo(tx - dx * HEAD_PX + dy * HEAD_PX * 0.6, ty - dy * HEAD_PX - dx * HEAD_PX * 0.6);
  ctx.closePath();
  ctx.fillStyle = colour;
  ctx.fill();
}
