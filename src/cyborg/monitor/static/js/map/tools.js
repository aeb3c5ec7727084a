// The map's pointer tools for acting on the robot, and what they draw over the map.
//
// - A click (press and release without moving) on a goal, dock or home marker sends the robot
//   there (home: the monitor's home command), whatever tool is chosen; hovering one says so.
// - "Go to pose" and "Set pose": press where the robot should be and drag towards its heading;
//   an arrow follows the pointer, and letting go sends (a press without a drag: no heading).
//   One use each, then the map pans again.
// - "Tour": each click adds a point (a drag gives it a heading), numbered on the map; Go sends
//   them all, Clear forgets them. A tour under way is drawn from the monitor's `tour` messages:
//   its points numbered, the ones already reached faded, the current leg ringed.
//
// Pointer events throughout, so a finger works as a mouse does. A tool takes a press only
// when the page may act (`actions.canAct`); otherwise a press pans the map as always.

const CLICK_PX = 5; // a press that moves less than this is a click
const CLICK_MS = 700;
const HEADING_PX = 10; // a drag shorter than this gives no heading
const HIT_PX = 12; // how near a marker a click must be
const COLOURS = { pose: "#188038", set: "#a142f4", tour: "#e8710a" };
const ONE_SHOT = new Set(["pose", "set"]);

export class MapTools {
  // `canvas`: the map's upper canvas; `view`: its ViewTransform; `actions`: MapActions;
  // `markerAt(sx, sy)`: the named goal, dock or home under a screen point, or null;
  // `robotAt(sx, sy)`: the robot under it, or null (a click on a robot selects it, even on a
  // marker: it never sends one); `schedule()`: draw a frame.
  constructor(canvas, { view, actions, markerAt, robotAt, schedule }) {
    this.canvas = canvas;
    this.view = view;
    this.actions = actions;
    this.markerAt = markerAt;
    this.robotAt = robotAt;
    this.schedule = schedule;
    this.mode = null; // "pose", "set", "tour" or null (pan)
    this.drag = null; // {id, start: [x, y] m, end: [x, y] m, sx, sy}
    this.press = null; // {id, sx, sy, at}: a press that may be a click
    this.points = []; // the tour being drawn: [x, y, θ or null]
    const root = canvas.parentElement;
    this.buttons = [...root.querySelectorAll("#map-act button[data-tool]")];
    for (const button of this.buttons) {
      button.addEventListener("click", () => this.setMode(this.mode === button.dataset.tool ? null : button.dataset.tool));
    }
    this.tourGo = root.querySelector("#map-tour-go");
    this.tourClear = root.querySelector("#map-tour-clear");
    this.tourGo.addEventListener("click", () => {
      if (!this.points.length) return;
      this.actions.startTour(this.points);
      this.points = [];
      this.setMode(null);
    });
    this.tourClear.addEventListener("click", () => { this.points = []; this.showTour(); });
    canvas.addEventListener("pointerdown", (event) => this.down(event));
    canvas.addEventListener("pointermove", (event) => this.move(event));
    canvas.addEventListener("pointerup", (event) => this.up(event));
    canvas.addEventListener("pointercancel", () => { this.drag = null; this.press = null; this.schedule(); });
  }

  setMode(mode) {
    this.mode = mode;
    for (const button of this.buttons) button.setAttribute("aria-pressed", String(button.dataset.tool === mode));
    this.canvas.classList.toggle("tool", mode !== null);
    this.showTour();
  }

  showTour() {
    const drawing = this.mode === "tour";
    this.tourGo.hidden = !drawing;
    this.tourClear.hidden = !drawing;
    this.tourGo.textContent = `Go (${this.points.length})`;
    this.tourGo.disabled = !this.points.length || !this.actions.canAct;
    this.schedule();
  }

  // Called by the view before it pans: true when a tool takes this press.
  claim(event) {
    if (this.mode === null || !this.actions.canAct || !event.isPrimary || (event.pointerType === "mouse" && event.button !== 0)) return false;
    const [sx, sy] = this.local(event);
    const at = this.view.toWorld(sx, sy);
    this.drag = { id: event.pointerId, start: at, end: at, sx, sy };
    try {
      this.canvas.setPointerCapture(event.pointerId);
    } catch {
      // a synthetic pointer: the drag works without capture
    }
    return true;
  }

  local(event) {
    const box = this.canvas.getBoundingClientRect();
    return [event.clientX - box.left, event.clientY - box.top];
  }

  down(event) {
    if (this.drag && this.drag.id === event.pointerId) return; // a tool's drag
    const [sx, sy] = this.local(event);
    this.press = event.isPrimary ? { id: event.pointerId, sx, sy, at: performance.now() } : null;
  }

  move(event) {
    const [sx, sy] = this.local(event);
    if (this.drag && this.drag.id === event.pointerId) {
      this.drag.end = this.view.toWorld(sx, sy);
      this.schedule();
      return;
    }
    if (this.press && this.press.id === event.pointerId && Math.hypot(sx - this.press.sx, sy - this.press.sy) > CLICK_PX) this.press = null;
    if (event.buttons === 0) this.hover(sx, sy);
  }

  // Whether a click is the tools' own: a tool is chosen. Such a click never selects another
  // robot (the pose goes to the robot selected when it was given).
  ownsClick() {
    return this.mode !== null;
  }

  // The marker a click at (sx, sy) would send the robot to, or null: none under it, or a robot
  // stands there (the click selects that robot instead).
  clickedMarker(sx, sy) {
    const marker = this.markerAt(sx, sy, HIT_PX);
    return marker && this.robotAt(sx, sy) === null ? marker : null;
  }

  hover(sx, sy) {
    const marker = this.clickedMarker(sx, sy);
    const ns = this.actions.robot();
    let title = "";
    if (marker) {
      const what = marker.home ? "send the robot home" : `send ${ns ?? "the robot"} to ${marker.name}`;
      title = this.actions.canAct ? `${marker.name}: click to ${what}` : `${marker.name} (${this.actions.whyNot()})`;
    }
    if (this.canvas.title !== title) this.canvas.title = title;
    this.canvas.classList.toggle("on-marker", !!marker && this.actions.canAct);
  }

  up(event) {
    const [sx, sy] = this.local(event);
    const drag = this.drag;
    if (drag && drag.id === event.pointerId) {
      this.drag = null;
      const long = Math.hypot(sx - drag.sx, sy - drag.sy) >= HEADING_PX;
      const [x, y] = drag.start;
      const th = long ? Math.atan2(drag.end[1] - y, drag.end[0] - x) : null;
      if (this.mode === "pose") this.actions.goPose(x, y, th);
      else if (this.mode === "set") this.actions.setPose(x, y, th);
      else if (this.mode === "tour") this.points.push([x, y, th]);
      if (ONE_SHOT.has(this.mode)) this.setMode(null);
      this.showTour();
      return;
    }
    const press = this.press;
    this.press = null;
    if (!press || press.id !== event.pointerId || performance.now() - press.at > CLICK_MS) return;
    const marker = this.clickedMarker(sx, sy);
    if (!marker || !this.actions.canAct) return;
    if (marker.home) this.actions.act({ t: "home" }, "home");
    else this.actions.go(marker.name);
  }

  // ------------------------------------------------------------------ drawing (CSS px)
  draw(ctx) {
    const tour = this.actions.tour;
    if (tour && tour.state === "running" && Array.isArray(tour.points)) {
      drawPoints(ctx, this.view, tour.points, COLOURS.tour, tour.leg);
    }
    if (this.points.length) drawPoints(ctx, this.view, this.points, COLOURS.tour, 0, true);
    const drag = this.drag;
    if (drag) {
      const [sx, sy] = this.view.toScreen(drag.start[0], drag.start[1]);
      const [ex, ey] = this.view.toScreen(drag.end[0], drag.end[1]);
      const long = Math.hypot(ex - sx, ey - sy) >= HEADING_PX;
      arrow(ctx, sx, sy, long ? Math.atan2(ey - sy, ex - sx) : null, Math.max(24, Math.hypot(ex - sx, ey - sy)), COLOURS[this.mode] || "#202124");
    }
  }
}

// Numbered points joined in order; `current` (from 1) is ringed, the ones before it faded.
function drawPoints(ctx, view, points, colour, current, draft = false) {
  const at = points.map(([x, y]) => view.toScreen(x, y));
  ctx.save();
  ctx.strokeStyle = colour;
  ctx.lineWidth = 2;
  ctx.setLineDash(draft ? [6, 4] : []);
  ctx.beginPath();
  at.forEach(([sx, sy], index) => (index ? ctx.lineTo(sx, sy) : ctx.moveTo(sx, sy)));
  ctx.stroke();
  ctx.setLineDash([]);
  ctx.font = "bold 11px system-ui, \"DejaVu Sans\", sans-serif";
  ctx.textAlign = "center";
  ctx.textBaseline = "middle";
  at.forEach(([sx, sy], index) => {
    const th = points[index][2];
    if (th !== null && th !== undefined) arrow(ctx, sx, sy, -th, 22, colour);
    ctx.globalAlpha = current && index + 1 < current ? 0.4 : 1;
    ctx.fillStyle = colour;
    ctx.beginPath();
    ctx.arc(sx, sy, 9, 0, 2 * Math.PI);
    ctx.fill();
    if (index + 1 === current) {
      ctx.lineWidth = 3;
      ctx.beginPath();
      ctx.arc(sx, sy, 13, 0, 2 * Math.PI);
      ctx.stroke();
    }
    ctx.fillStyle = "#fff";
    ctx.fillText(String(index + 1), sx, sy + 0.5);
  });
  ctx.restore();
}

// An arrow from (sx, sy) at screen angle `angle` (null: a dot only), `length` px long.
function arrow(ctx, sx, sy, angle, length, colour) {
  ctx.save();
  ctx.strokeStyle = colour;
  ctx.fillStyle = colour;
  ctx.lineWidth = 3;
  ctx.beginPath();
  ctx.arc(sx, sy, 5, 0, 2 * Math.PI);
  ctx.fill();
  if (angle !== null) {
    const ex = sx + Math.cos(angle) * length, ey = sy + Math.sin(angle) * length;
    ctx.beginPath();
    ctx.moveTo(sx, sy);
    ctx.lineTo(ex, ey);
    ctx.stroke();
    ctx.beginPath();
    ctx.moveTo(ex, ey);
    ctx.lineTo(ex - Math.cos(angle - 0.45) * 10, ey - Math.sin(angle - 0.45) * 10);
    ctx.lineTo(ex - Math.cos(angle + 0.45) * 10, ey - Math.sin(angle + 0.45) * 10);
    ctx.closePath();
    ctx.fill();
  }
  ctx.restore();
}
