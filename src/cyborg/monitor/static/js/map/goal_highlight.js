// The goal that the node selected in the tree names, ringed on the map: the tree and the map
// speak to each other.
//
// The page hands over the names a node's properties give (js/node_goals.js: MoveTo's
// `location` first); the first of them that names a goal, dock or home of the map shown is the
// target. It is drawn over everything that moves: two rings in a strong colour that pulse for
// PULSE_MS after the selection and then stay, steady, until another node is selected (one that
// names no goal clears it). When the target lies off screen, within MARGIN_PX of an edge or
// under one of the map's controls (the toolbar, the actions' bar, STOP: free_area.js), the view
// pans to it, once per selection; a map that loads later is searched again.

import { CATEGORY } from "./map_model.js";

const PULSE_MS = 1600;
const MARGIN_PX = 24;
const RING_PX = 16;
const COLOUR = "#f9ab00";
const NAMED = new Set([CATEGORY.GOAL, CATEGORY.GOAL_WITH_HEADING, CATEGORY.DOCK, CATEGORY.HOME, CATEGORY.OTHER]);

export class GoalHighlight {
  constructor() {
    this.names = [];
    this.since = 0; // when the selection came (performance.now())
    this.target = null; // {name, x, y, th, category} on the map shown, or null
    this.searched = null; // the map the target was looked for in
    this.revealed = false;
  }

  // The names a newly selected node gives, most likely first; [] clears the highlight.
  set(names) {
    this.names = Array.isArray(names) ? names.filter((n) => typeof n === "string" && n).slice(0, 16) : [];
    this.since = performance.now();
    this.target = null;
    this.searched = null;
    this.revealed = false;
  }

  // The target on `map` (a parsed map, or null): looked up again when the map changed.
  resolve(map) {
    if (map === this.searched) return this.target;
    this.searched = map;
    this.target = null;
    if (!map || !this.names.length) return null;
    for (const name of this.names) {
      const found = map.objects.find((item) => item.name === name && NAMED.has(item.category) && !item.outline.length);
      if (found) {
        this.target = { name: found.name, x: found.x, y: found.y, th: found.th, category: found.category };
        break;
      }
    }
    return this.target;
  }

  // Pans `view` so the target is on screen and clear of the boxes `covered` ([x0, y0, x1, y1],
  // CSS px: the map's controls), once per selection; true when it moved the view.
  reveal(view, covered = []) {
    if (!this.target || this.revealed || !view.width) return false;
    this.revealed = true;
    const [sx, sy] = view.toScreen(this.target.x, this.target.y);
    const hidden = covered.some(([x0, y0, x1, y1]) => sx + RING_PX > x0 && sx - RING_PX < x1 && sy + RING_PX > y0 && sy - RING_PX < y1);
    if (!hidden && sx >= MARGIN_PX && sy >= MARGIN_PX && sx <= view.width - MARGIN_PX && sy <= view.height - MARGIN_PX) return false;
    view.centerOn(this.target.x, this.target.y);
    return true;
  }

  // Draws the rings on `ctx` (already in CSS px); true while it pulses (another frame wanted).
  draw(ctx, view, now = performance.now()) {
    if (!this.target) return false;
    const [sx, sy] = view.toScreen(this.target.x, this.target.y);
    const age = now - this.since;
    const pulsing = age < PULSE_MS;
    const wave = pulsing ? (age % (PULSE_MS / 2)) / (PULSE_MS / 2) : 0;
    ctx.lineWidth = 3;
    ctx.strokeStyle = COLOUR;
    ctx.beginPath();
    ctx.arc(sx, sy, RING_PX, 0, 2 * Math.PI);
    ctx.stroke();
    ctx.globalAlpha = pulsing ? 1 - wave : 0.6;
    ctx.beginPath();
    ctx.arc(sx, sy, RING_PX + 4 + (pulsing ? 18 * wave : 4), 0, 2 * Math.PI);
    ctx.stroke();
    ctx.globalAlpha = 1;
    return pulsing;
  }
}
