// Where the map's names go: every label of a frame (robots, tracked and detected objects, docks,
// home, goals, named areas) is placed here, after everything else is drawn, so that no label
// covers another. As RViz and Foxglove users expect, a name sits beside what it names, and a
// crowded spot stays readable: labels are placed one by one, most important first, each at the
// first spot around its marker where it covers no label placed before it:
//
//   robots  >  tracked and detected objects (people and things)  >  docks and home
//           >  goals (the one a robot drives to first)  >  named areas
//
// (PRIORITY below; the selected robot goes first among robots, the most confident objects
// first among objects). The spots, in order: beside the marker on the label's own preferred
// side, then the other sides and corners; then, when all of those are taken, a spot slid along
// a side (up to two box sizes) or further out (two more rings), nearer ones first, with a thin
// leader line back to the marker. A spot that covers a marker (a robot, a goal dot, an object)
// is taken only when no spot is clear of markers too. A label with no free spot is left out:
// the lower one gives way. Every spot lies inside the canvas, clear of the map's controls.
//
// The boxes placed in the last frame (CSS px, halo included, with kind and text) are what
// `window.__map.labels()` returns, so a test can measure that none overlap.

export const PRIORITY = { robot: 0, tracked: 1, detection: 1, dock: 2, home: 2, goal: 3, area: 4 };
const LINE_PX = 14; // one line of text
const HALO_PX = 2; // the white outline around the text, and a hair of air
const LEADER_STEP_PX = 18; // each further ring is this much further out
const LEADER_RINGS = 2;
const MARKER_AIR_PX = 6; // labels keep this far off others' markers where they can
const SLIDES = 4; // half box sizes a spot may slide along its side, either way
const GRID_PX = 48; // the cells boxes are filed by (BoxGrid)
const GRID_ROW = 1 << 16; // a cell's number: column · GRID_ROW + row
const LEADER = "rgba(60, 64, 67, 0.7)";
const HALO = "rgba(255, 255, 255, 0.92)";
const DIAGONAL = Math.SQRT1_2;

// Sides: [dx, dy] unit steps from the marker (screen y down).
const SIDES = {
  E: [1, 0], W: [-1, 0], N: [0, -1], S: [0, 1],
  NE: [DIAGONAL, -DIAGONAL], SE: [DIAGONAL, DIAGONAL], NW: [-DIAGONAL, -DIAGONAL], SW: [-DIAGONAL, DIAGONAL],
};
const ALL_SIDES = ["E", "W", "N", "S", "NE", "SE", "NW", "SW"];
const widths = new Map(); // font + text -> width, px
const MAX_WIDTHS = 4000;

// One frame's labels. `width`, `height`: the canvas, CSS px; `covered`: boxes the map's
// controls cover ([x0, y0, x1, y1], free_area.js), where a label would be hidden.
export class LabelLayout {
  constructor(width, height, covered = []) {
    this.width = width;
    this.height = height;
    this.covered = covered;
    this.markers = []; // [x0, y0, x1, y1] around what is drawn, that labels should keep off
    this.wanted = [];
  }

  // A marker drawn at (sx, sy) reaching `radius` px: other labels keep off it, and a little
  // further (MARKER_AIR_PX, so that none reads as its name), where they can. Returns its index
  // (a label names its own marker with it).
  marker(sx, sy, radius) {
    const r = radius + MARKER_AIR_PX;
    this.markers.push([sx - r, sy - r, sx + r, sy + r]);
    return this.markers.length - 1;
  }

  // A label: `kind` (a PRIORITY key), `lines` [{text, font, colour}], `at` [sx, sy] the point it
  // names, `gap` px from that point to the nearest edge of the text, `sides` the preferred
  // sides first (the rest follow), `own` the index of its marker, `alpha`, `rank` (lower goes
  // first within a kind).
  add(label) {
    this.wanted.push({ sides: [], own: -1, alpha: 1, rank: 0, ...label, order: this.wanted.length });
  }

  // Places the labels (measured with `ctx`): the placed ones, each with its `box` [x0, y0, x1,
  // y1] (halo included), `align` and `leader` (null, or the [x, y] on the box the line meets).
  place(ctx) {
    const queue = [...this.wanted].sort((a, b) => PRIORITY[a.kind] - PRIORITY[b.kind] || a.rank - b.rank || a.order - b.order);
    this.markerGrid = new BoxGrid();
    this.markers.forEach((box, i) => this.markerGrid.add(box, i));
    const taken = new BoxGrid();
    const placed = [];
    for (const label of queue) {
      const size = measure(ctx, label.lines);
      const spot = this.spotFor(label, size, taken);
      if (!spot) continue;
      placed.push({ ...label, ...spot, size });
      taken.add(spot.box, placed.length);
    }
    return placed;
  }

  // The first spot for `label` of `size` that lies in the canvas, off the controls, and covers
  // no box `taken` (a BoxGrid of the labels placed), preferring those clear of markers; or null.
  spotFor(label, size, taken) {
    const sides = [...label.sides, ...ALL_SIDES.filter((side) => !label.sides.includes(side))];
    const free = (box) => box[0] >= 0 && box[1] >= 0 && box[2] <= this.width && box[3] <= this.height
      && !this.covered.some((other) => overlaps(box, other)) && !taken.hits(box, -1);
    // the first free spot of `spots` clear of markers, else the first free one (or null)
    const first = (spots) => {
      let fallback = null;
      for (const s of spots) {
        if (!free(s.box)) continue;
        if (!this.markerGrid.hits(s.box, label.own)) return [s, s];
        fallback ??= s;
      }
      return [null, fallback];
    };
    const [beside, besideFallback] = first(sides.map((side) => spot(label, size, side, 0, 0)));
    if (beside) return beside;
    const [away, awayFallback] = first(farSpots(label, size, sides));
    return away ?? besideFallback ?? awayFallback;
  }
}

// Boxes ([x0, y0, x1, y1]) filed by the GRID_PX cells they touch, so that asking what a box
// overlaps looks only at its own cells: a crowd of markers costs little more than a few.
class BoxGrid {
  constructor() {
    this.cells = new Map(); // cell number -> [box, id, box, id, ...]
  }

  add(box, id) {
    const [cx0, cy0, cx1, cy1] = cellsOf(box);
    for (let cx = cx0; cx <= cx1; cx++) {
      for (let cy = cy0; cy <= cy1; cy++) {
        const key = cx * GRID_ROW + cy;
        const cell = this.cells.get(key);
        if (cell) cell.push(box, id);
        else this.cells.set(key, [box, id]);
      }
    }
  }

  // Whether `box` overlaps a box filed here, other than the one of id `skip`.
  hits(box, skip) {
    const [cx0, cy0, cx1, cy1] = cellsOf(box);
    for (let cx = cx0; cx <= cx1; cx++) {
      for (let cy = cy0; cy <= cy1; cy++) {
        const cell = this.cells.get(cx * GRID_ROW + cy);
        if (!cell) continue;
        for (let i = 0; i < cell.length; i += 2) if (cell[i + 1] !== skip && overlaps(box, cell[i])) return true;
      }
    }
    return false;
  }
}

// The cells a box touches: [cx0, cy0, cx1, cy1], inclusive.
function cellsOf([x0, y0, x1, y1]) {
  return [Math.floor(x0 / GRID_PX), Math.floor(y0 / GRID_PX), Math.floor(x1 / GRID_PX), Math.floor(y1 / GRID_PX)];
}

// The spots away from the marker, tied to it by a leader line, nearer first: on each side slid
// along it (up to SLIDES half box sizes either way), then further out (LEADER_RINGS rings),
// there slid as well. Made one at a time: most labels take one of the first.
function* farSpots(label, size, sides) {
  for (let ring = 0; ring <= LEADER_RINGS; ring++) {
    for (let step = 0; step <= SLIDES; step++) {
      if (!ring && !step) continue;
      for (const side of sides) {
        yield spot(label, size, side, ring, step);
        if (step) yield spot(label, size, side, ring, -step);
      }
    }
  }
}

// The text's size: the widest line, and a line height each; halo included.
function measure(ctx, lines) {
  let widest = 0;
  for (const { text, font } of lines) {
    const key = `${font}\n${text}`;
    let width = widths.get(key);
    if (width === undefined) {
      ctx.font = font;
      width = ctx.measureText(text).width;
      if (widths.size >= MAX_WIDTHS) widths.clear();
      widths.set(key, width);
    }
    widest = Math.max(widest, width);
  }
  return { w: widest + 2 * HALO_PX, h: lines.length * LINE_PX + 2 * HALO_PX };
}

// The label's box on `side`, `ring` rings further out than beside its marker and slid `slide`
// half box sizes along the side (across it: up or down beside E and W, sideways above N or
// below S; both ways at a corner).
function spot(label, { w, h }, side, ring, slide) {
  const [dx, dy] = SIDES[side];
  const reach = label.gap + ring * LEADER_STEP_PX;
  const [sx, sy] = label.at;
  // the point `reach` px out along the side, then the box hung from it on that side
  const px = sx + dx * reach, py = sy + dy * reach;
  let x0 = dx > 0.1 ? px : dx < -0.1 ? px - w : px - w / 2;
  let y0 = dy > 0.1 ? py : dy < -0.1 ? py - h : py - h / 2;
  if (Math.abs(dx) > 0.1) y0 += (slide * h) / 2;
  if (Math.abs(dy) > 0.1 && Math.abs(dx) <= 0.1) x0 += (slide * w) / 2;
  const box = [x0, y0, x0 + w, y0 + h];
  const align = dx > 0.1 ? "left" : dx < -0.1 ? "right" : "center";
  const leader = ring || slide ? [Math.min(Math.max(sx, box[0]), box[2]), Math.min(Math.max(sy, box[1]), box[3])] : null;
  return { box, align, leader };
}

export function overlaps(a, b) {
  return a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
}

// Draws the placed labels: leader lines first, then each text with a white halo.
export function drawLabels(ctx, placed) {
  ctx.lineCap = "round";
  for (const label of placed) {
    if (!label.leader) continue;
    const [sx, sy] = label.at, [lx, ly] = label.leader;
    const length = Math.hypot(lx - sx, ly - sy);
    if (length < 1) continue;
    const start = Math.min(label.gap * 0.6, length); // from the marker's edge, not its middle
    ctx.globalAlpha = label.alpha;
    ctx.beginPath();
    ctx.moveTo(sx + ((lx - sx) * start) / length, sy + ((ly - sy) * start) / length);
    ctx.lineTo(lx, ly);
    ctx.strokeStyle = LEADER;
    ctx.lineWidth = 1;
    ctx.stroke();
  }
  ctx.textBaseline = "middle";
  ctx.lineJoin = "round";
  for (const label of placed) {
    const [x0, y0, x1] = label.box;
    const x = label.align === "left" ? x0 + HALO_PX : label.align === "right" ? x1 - HALO_PX : (x0 + x1) / 2;
    ctx.textAlign = label.align;
    ctx.globalAlpha = label.alpha;
    label.lines.forEach(({ text, font, colour }, i) => {
      const y = y0 + HALO_PX + LINE_PX / 2 + i * LINE_PX;
      ctx.font = font;
      ctx.lineWidth = 3;
      ctx.strokeStyle = HALO;
      ctx.strokeText(text, x, y);
      ctx.fillStyle = colour;
      ctx.fillText(text, x, y);
    });
  }
  ctx.globalAlpha = 1;
  ctx.textAlign = "left";
}

// What `window.__map.labels()` gives: each placed label's kind, text (lines joined by " / "),
// box (CSS px on the canvas) and whether a leader line ties it to its marker.
export function labelBoxes(placed) {
  return placed.map(({ kind, lines, box, leader }) => ({
    kind, text: lines.map((line) => line.text).join(" / "),
    x0: box[0], y0: box[1], x1: box[2], y1: box[3], leader: leader !== null,
  }));
}
