// Draws a behaviour tree top-down in SVG and keeps it coloured by status.
//
// Layout is d3-hierarchy's tidy tree with a separation that knows each box's width. What is
// drawn follows rqt_bt's Draw depth (subtrees nested deeper than N are folded into one node)
// plus per-node folding (double-click), and the running path is always unfolded unless the
// user folded it by hand. Status updates only change class names, so a 1,000-node tree takes
// a live stream without redrawing.
//
// The tree is shown to be read, as Groot2 shows it: at READABLE_SCALE (labels at 12 px),
// placed with its root at the top and the running path in view; the user pans (drag, wheel)
// and zooms, "Fit all" fits on request. Where the tree is larger than the view an
// overview (a minimap: every box, the running path, the part in view) sits in the corner; a
// click or drag there moves the view. When the running path moves off-screen it is scrolled
// into view, unless the user has panned or zoomed in the last FOLLOW_PAUSE_MS; while part of it
// is off-screen (a parent far to the side of its running child), a bar at the top names the
// whole path, each name a button that brings its node into view.

import { hierarchy, tree as tidyTree } from "../vendor/d3-hierarchy.min.mjs";

const BOX_HEIGHT = 28;
const ROW_GAP = 46;
const CHAR_PX = 7;
const PAD_PX = 18;
const SIBLING_GAP = 14;
const MAX_LABEL = 40;
const FAR_SCALE = 0.35;
const READABLE_SCALE = 1;
const FOLLOW_PAUSE_MS = 3000;
const EDGE_MARGIN = 24;
const OVERVIEW_WIDTH = 200;
const OVERVIEW_HEIGHT = 120;
const OVERVIEW_MIN_HEIGHT = 36;
const STATE_CLASSES = / (s\d|fresh|never|active|inside-active|hooked|paused)\b/g;

export class TreeView {
  // `badge(node, width)`: extra markup drawn in a node's box (the services' badge), or "".
  constructor(svg, { onSelect, onToggle, onUserZoom, badge = () => "" }) {
    this.svg = svg;
    this.viewport = svg.querySelector("#viewport");
    this.edgeLayer = svg.querySelector("#edges");
    this.nodeLayer = svg.querySelector("#nodes");
    this.onSelect = onSelect;
    this.onToggle = onToggle;
    this.onUserZoom = onUserZoom;
    this.badge = badge;
    this.badges = new Map(); // id -> the <g> of its badge
    this.transform = { k: 1, x: 0, y: 0 };
    this.bounds = { x0: 0, y0: 0, x1: 1, y1: 1 };
    this.elements = new Map(); // id -> <g>
    this.positions = new Map(); // id -> its laid-out d3 node (x: centre, y: top, width)
    this.edges = new Map(); // child id -> <path>
    this.highlight = true;
    this.size = { width: 0, height: 0 };
    this.userMovedAt = -Infinity; // performance.now() of the user's last pan or zoom
    this.placedAt = -Infinity; // and of the last place()
    this.dragging = false;
    this.overview = svg.parentNode.querySelector("#tree-overview");
    this.overviewCanvas = this.overview.querySelector("canvas");
    this.lens = this.overview.querySelector(".lens");
    this.overviewScale = { x: 1, y: 1 };
    this.overviewActive = null; // the active set the overview was drawn with
    this.pathBar = svg.parentNode.querySelector("#tree-path");
    this.pathIds = []; // the running path as drawn, root first
    this.pathKey = null; // what the path bar shows
    new ResizeObserver(([entry]) => {
      this.size = { width: entry.contentRect.width, height: entry.contentRect.height };
      this.placeLens();
    }).observe(svg);
    this.listen();
  }

  // d3's tidy layout of what `isOpen` leaves unfolded under `root`, each node with its `label`
  // and box `width`.
  layOut(root, isOpen) {
    const layoutRoot = hierarchy(root, (node) => (isOpen(node) ? node.children : null));
    layoutRoot.each((d) => {
      const label = displayLabel(d.data, !isOpen(d.data) && d.data.children.length > 0);
      d.label = label;
      d.width = label.length * CHAR_PX + PAD_PX;
    });
    tidyTree()
      .nodeSize([1, BOX_HEIGHT + ROW_GAP])
      .separation((a, b) => (a.width + b.width) / 2 + (a.parent === b.parent ? SIBLING_GAP : SIBLING_GAP * 2))(layoutRoot);
    return layoutRoot;
  }

  // Whether the tree, folded as `isOpen` says, fits the view's width at the readable scale.
  fitsReadable(root, isOpen) {
    if (!this.size.width) this.measure();
    let x0 = Infinity, x1 = -Infinity;
    this.layOut(root, isOpen).each((d) => {
      x0 = Math.min(x0, d.x - d.width / 2);
      x1 = Math.max(x1, d.x + d.width / 2);
    });
    return (x1 - x0 + 2 * EDGE_MARGIN) * READABLE_SCALE <= this.size.width;
  }

  // Lay out and draw `root` (the structure's root), showing only nodes for which
  // `isOpen(parent)` held all the way down, in the state `look` gives (see paint()). The
  // markup is built as one string with its classes in place: one parse, one style pass.
  // Returns the number of nodes drawn.
  draw(root, isOpen, look) {
    // The view's size must be known before the markup goes in, so that fit() (called after
    // drawing) never asks the DOM: with the new nodes inserted, that question forces a
    // synchronous layout of every box and of every label, labels that the fit may then hide
    // (svg.far) before the frame would ever have shown them. Until the ResizeObserver has
    // spoken (the first frame, while the page's modules and the tree arrive together) the size
    // is read here, from a view that is still empty and cheap to lay out.
    if (!this.size.width) this.measure();
    const layoutRoot = this.layOut(root, isOpen);
    let x0 = Infinity, x1 = -Infinity, y1 = 0;
    const nodes = [];
    const edges = [];
    layoutRoot.each((d) => {
      x0 = Math.min(x0, d.x - d.width / 2);
      x1 = Math.max(x1, d.x + d.width / 2);
      y1 = Math.max(y1, d.y + BOX_HEIGHT);
      const id = d.data.id;
      const folded = !isOpen(d.data) && d.data.children.length > 0;
      nodes.push(
        `<g class="${stateClass(`node c-${d.data.category}${folded ? " folded" : ""}`, id, look)}" data-id="${escapeHtml(id)}" ` +
          `transform="translate(${d.x - d.width / 2},${d.y})">` +
          `<rect width="${d.width}" height="${BOX_HEIGHT}"></rect>` +
          `<text x="${d.width / 2}" y="${BOX_HEIGHT / 2 + 1}">${escapeHtml(d.label)}</text>${this.badge(d.data, d.width)}</g>`,
      );
      if (d.parent) {
        const px = d.parent.x, py = d.parent.y + BOX_HEIGHT, my = (py + d.y) / 2;
        const on = look.active.has(id) && look.active.has(d.parent.data.id);
        edges.push(
          `<path class="edge${on ? " active" : ""}" data-parent="${escapeHtml(d.parent.data.id)}" data-child="${escapeHtml(id)}" ` +
            `d="M${px},${py}C${px},${my} ${d.x},${my} ${d.x},${d.y}"></path>`,
        );
      }
    });
    this.edgeLayer.innerHTML = edges.join("");
    this.nodeLayer.innerHTML = nodes.join("");
    this.elements = new Map();
    for (const g of this.nodeLayer.children) this.elements.set(g.dataset.id, g);
    this.badges = new Map();
    for (const g of this.nodeLayer.querySelectorAll("g.svc")) this.badges.set(g.parentNode.dataset.id, g);
    this.edges = new Map();
    for (const path of this.edgeLayer.children) this.edges.set(path.dataset.child, path);
    this.bounds = { x0: x0 - 20, y0: -20, x1: x1 + 20, y1: y1 + 20 };
    this.layoutRoot = layoutRoot;
    this.positions = new Map();
    layoutRoot.each((d) => this.positions.set(d.data.id, d));
    this.drawOverview(look.active);
    return nodes.length;
  }

  clear() {
    this.edgeLayer.innerHTML = "";
    this.nodeLayer.innerHTML = "";
    this.elements = new Map();
    this.edges = new Map();
    this.badges = new Map();
    this.layoutRoot = null;
    this.positions = new Map();
    this.overview.hidden = true;
    return 0;
  }

  // Show the state of the nodes `ids` (all drawn nodes when null). `look` gives
  // code(id): status (0-4) + 8 when ticked in the latest tick; active, inside (folded nodes
  // with the running path inside) and hooked: Sets of ids; pausedAt: an id or "".
  paint(ids, look) {
    const which = ids === null ? this.elements.keys() : ids;
    for (const id of which) {
      const g = this.elements.get(id);
      if (!g) continue;
      const cls = stateClass(g.getAttribute("class").replace(STATE_CLASSES, ""), id, look);
      if (cls !== g.getAttribute("class")) g.setAttribute("class", cls);
      const path = this.edges.get(id);
      if (path) path.classList.toggle("active", look.active.has(id) && look.active.has(path.dataset.parent));
    }
    if (look.active !== this.overviewActive) this.drawOverview(look.active);
  }

  // Badges of the composites `ids` marked running (`on`), the others not.
  markServices(on, ids) {
    for (const id of ids) this.badges.get(id)?.classList.toggle("on", on.has(id));
  }

  markClass(name, ids) {
    for (const [id, g] of this.elements) g.classList.toggle(name, ids.has(id));
  }

  // ------------------------------------------------------------------ zoom and pan
  apply() {
    const { k, x, y } = this.transform;
    this.viewport.setAttribute("transform", `translate(${x},${y}) scale(${k})`);
    // Labels smaller than ~4 px cannot be read: leave them out (and their layout) until
    // the user zooms in.
    this.svg.classList.toggle("far", k < FAR_SCALE);
    this.placeLens();
    this.showPathBar();
  }

  // The running path drawn (`ids`, root first), for the path bar.
  setPath(ids) {
    this.pathIds = ids;
    this.pathKey = null;
    this.showPathBar();
  }

  // The path bar: shown while a node of the running path is wholly off-screen; redrawn only
  // when what it shows changes (apply() calls it at every step of a pan).
  showPathBar() {
    const { width, height } = this.size;
    const { k, x, y } = this.transform;
    const off = this.pathIds.map((id) => {
      const d = this.positions.get(id);
      if (!d || !width) return false;
      const left = x + (d.x - d.width / 2) * k, top = y + d.y * k;
      return left + d.width * k < 0 || left > width || top + BOX_HEIGHT * k < 0 || top > height;
    });
    const key = `${this.pathIds.join("\u0000")}\u0001${off.join()}`;
    if (key === this.pathKey) return;
    this.pathKey = key;
    this.pathBar.hidden = !off.includes(true);
    this.pathBar.innerHTML = this.pathBar.hidden ? "" : this.pathIds.map((id, i) =>
      `<button class="${off[i] ? "off" : "on"}" data-id="${escapeHtml(id)}" title="Show it">${escapeHtml(this.positions.get(id).label)}</button>`,
    ).join("<span>›</span>");
  }

  // The tree at the readable scale, its root at the top, centred when it fits the width, else
  // with `focusId` (the end of the running path, or the root) and as many of its parents as fit
  // in the middle. Returns false while the view has no size yet (a hidden tab): place it again
  // once it has one.
  place(focusId) {
    if (!this.size.width) this.measure();
    const { width, height } = this.size;
    if (!width || !height || !this.layoutRoot) return false;
    const k = READABLE_SCALE;
    const b = this.bounds;
    let x;
    if ((b.x1 - b.x0) * k <= width) x = (width - (b.x1 - b.x0) * k) / 2 - b.x0 * k;
    else {
      let d = this.positions.get(focusId) || this.layoutRoot;
      let left = d.x - d.width / 2, right = d.x + d.width / 2;
      for (d = d.parent; d; d = d.parent) {
        const wider = [Math.min(left, d.x - d.width / 2), Math.max(right, d.x + d.width / 2)];
        if ((wider[1] - wider[0]) * k > width - 2 * EDGE_MARGIN) break;
        [left, right] = wider;
      }
      x = width / 2 - ((left + right) / 2) * k;
      x = Math.min(-b.x0 * k, Math.max(width - b.x1 * k, x)); // no empty margin beyond the tree
    }
    this.transform = { k, x, y: -b.y0 * k };
    this.placedAt = performance.now();
    this.apply();
    if (focusId) this.reveal(focusId, { force: true });
    return true;
  }

  // Whether the user panned or zoomed since the tree was last placed.
  movedByUser() {
    return this.userMovedAt >= this.placedAt;
  }

  // Whether the user panned or zoomed in the last FOLLOW_PAUSE_MS (or is dragging now).
  userIsPanning() {
    return this.dragging || performance.now() - this.userMovedAt < FOLLOW_PAUSE_MS;
  }

  // Scroll the node `id` into view when it is (partly) off-screen, unless the user is panning
  // (`force`: even then). Returns whether the view moved.
  reveal(id, { force = false } = {}) {
    const d = this.positions.get(id);
    if (!d || (!force && this.userIsPanning())) return false;
    const { width, height } = this.size;
    if (!width || !height) return false;
    const { k, x, y } = this.transform;
    const left = x + (d.x - d.width / 2) * k, right = x + (d.x + d.width / 2) * k;
    const top = y + d.y * k, bottom = y + (d.y + BOX_HEIGHT) * k;
    let dx = 0, dy = 0;
    if (left < EDGE_MARGIN || right > width - EDGE_MARGIN) dx = width / 2 - (left + right) / 2;
    if (top < EDGE_MARGIN || bottom > height - EDGE_MARGIN) dy = height / 2 - (top + bottom) / 2;
    if (!dx && !dy) return false;
    this.transform = { k, x: x + dx, y: y + dy };
    this.apply();
    return true;
  }

  // ------------------------------------------------------------------ the overview
  // Every drawn box in miniature, the running path in its colour; redrawn with each layout and
  // when the running path changes. Shown only while the tree is larger than the view.
  drawOverview(active) {
    this.overviewActive = active;
    const b = this.bounds, canvas = this.overviewCanvas;
    if (!this.layoutRoot) return;
    const width = b.x1 - b.x0, height = b.y1 - b.y0;
    const scale = Math.min(OVERVIEW_WIDTH / width, OVERVIEW_HEIGHT / height);
    const cw = Math.max(1, Math.round(width * scale));
    const ch = Math.max(OVERVIEW_MIN_HEIGHT, Math.round(height * scale));
    this.overviewScale = { x: cw / width, y: ch / height };
    if (canvas.width !== cw || canvas.height !== ch) {
      canvas.width = cw;
      canvas.height = ch;
    }
    const context = canvas.getContext("2d");
    context.clearRect(0, 0, cw, ch);
    const sx = this.overviewScale.x, sy = this.overviewScale.y;
    for (const pass of [false, true]) { // the running path over the rest
      context.fillStyle = pass ? "#e37400" : "#9aa0a6";
      for (const d of this.positions.values()) {
        if (active.has(d.data.id) !== pass) continue;
        context.fillRect((d.x - d.width / 2 - b.x0) * sx, (d.y - b.y0) * sy,
          Math.max(1, d.width * sx), Math.max(2, BOX_HEIGHT * sy));
      }
    }
    this.placeLens();
  }

  // The overview's frame of what the view shows; the overview shows only while it matters.
  placeLens() {
    if (!this.layoutRoot || !this.size.width) return;
    const { k, x, y } = this.transform;
    const b = this.bounds, { width, height } = this.size;
    const larger = (b.x1 - b.x0) * k > width + 1 || (b.y1 - b.y0) * k > height + 1;
    this.overview.hidden = !larger;
    if (!larger) return;
    const sx = this.overviewScale.x, sy = this.overviewScale.y;
    const cw = this.overviewCanvas.width, ch = this.overviewCanvas.height;
    const left = Math.max(0, (-x / k - b.x0) * sx), top = Math.max(0, (-y / k - b.y0) * sy);
    const right = Math.min(cw, ((width - x) / k - b.x0) * sx), bottom = Math.min(ch, ((height - y) / k - b.y0) * sy);
    Object.assign(this.lens.style, {
      left: `${left}px`, top: `${top}px`, width: `${Math.max(2, right - left)}px`, height: `${Math.max(2, bottom - top)}px`,
    });
  }

  // Centre the view on the overview's point (ox, oy), as a pan by the user.
  panToOverview(ox, oy) {
    const b = this.bounds, { k } = this.transform;
    const tx = b.x0 + ox / this.overviewScale.x, ty = b.y0 + oy / this.overviewScale.y;
    this.transform = { k, x: this.size.width / 2 - tx * k, y: this.size.height / 2 - ty * k };
    this.userMovedAt = performance.now();
    this.apply();
    this.onUserZoom();
  }

  // The view's size, from the DOM (a layout if one is due); the ResizeObserver keeps it after.
  measure() {
    const { width, height } = this.svg.getBoundingClientRect();
    this.size = { width, height };
  }

  // Fit the whole drawing in the view (`byUser`: asked for, so kept as a pan of the user's).
  fit(byUser = false) {
    // The size comes from the ResizeObserver, or from draw(): asking the DOM here would force a
    // layout of everything just drawn.
    if (!this.size.width) this.measure();
    const box = this.size;
    const width = this.bounds.x1 - this.bounds.x0, height = this.bounds.y1 - this.bounds.y0;
    if (!box.width || !box.height) return;
    const k = Math.min(box.width / width, box.height / height, 1.5);
    this.transform = {
      k,
      x: (box.width - width * k) / 2 - this.bounds.x0 * k,
      y: Math.max(0, (box.height - height * k) / 2) - this.bounds.y0 * k,
    };
    if (byUser) this.userMovedAt = performance.now();
    this.apply();
  }

  centerOn(id, byUser = false) {
    const d = this.positions.get(id);
    if (!d) return;
    if (byUser) this.userMovedAt = performance.now();
    if (!this.size.width) this.measure();
    const k = Math.max(this.transform.k, READABLE_SCALE);
    this.transform = { k, x: this.size.width / 2 - d.x * k, y: this.size.height / 3 - d.y * k };
    this.apply();
  }

  listen() {
    const svg = this.svg;
    svg.addEventListener("wheel", (event) => {
      event.preventDefault();
      const box = svg.getBoundingClientRect();
      const px = event.clientX - box.left, py = event.clientY - box.top;
      const factor = Math.exp(-event.deltaY * 0.0015);
      const t = this.transform;
      const k = Math.min(Math.max(t.k * factor, 0.02), 4);
      this.transform = { k, x: px - ((px - t.x) * k) / t.k, y: py - ((py - t.y) * k) / t.k };
      this.userMovedAt = performance.now();
      this.apply();
      this.onUserZoom();
    }, { passive: false });
    let drag = null;
    svg.addEventListener("pointerdown", (event) => {
      if (event.target.closest("g.node")) return;
      drag = { x: event.clientX, y: event.clientY, t: { ...this.transform } };
      this.dragging = true;
      svg.classList.add("dragging");
    });
    window.addEventListener("pointermove", (event) => {
      if (!drag) return;
      this.transform = { ...drag.t, x: drag.t.x + event.clientX - drag.x, y: drag.t.y + event.clientY - drag.y };
      this.apply();
    });
    window.addEventListener("pointerup", () => {
      if (drag && (this.transform.x !== drag.t.x || this.transform.y !== drag.t.y)) {
        this.userMovedAt = performance.now();
        this.onUserZoom();
      }
      drag = null;
      this.dragging = false;
      svg.classList.remove("dragging");
    });
    let overviewDrag = false;
    const overviewPan = (event) => {
      const box = this.overviewCanvas.getBoundingClientRect();
      this.panToOverview(event.clientX - box.left, event.clientY - box.top);
    };
    this.overview.addEventListener("pointerdown", (event) => {
      overviewDrag = true;
      this.dragging = true;
      try {
        this.overview.setPointerCapture(event.pointerId);
      } catch {
        // a synthetic pointer: drag without capture
      }
      overviewPan(event);
      event.preventDefault();
    });
    this.overview.addEventListener("pointermove", (event) => { if (overviewDrag) overviewPan(event); });
    const endOverviewDrag = () => {
      if (!overviewDrag) return;
      overviewDrag = false;
      this.dragging = false;
      this.userMovedAt = performance.now();
    };
    this.overview.addEventListener("pointerup", endOverviewDrag);
    this.pathBar.addEventListener("click", (event) => {
      const button = event.target.closest("button[data-id]");
      if (!button) return;
      this.centerOn(button.dataset.id, true);
      this.onUserZoom();
    });
    this.overview.addEventListener("pointercancel", endOverviewDrag);
    this.nodeLayer.addEventListener("click", (event) => {
      const g = event.target.closest("g.node");
      if (g) this.onSelect(g.dataset.id);
    });
    this.nodeLayer.addEventListener("dblclick", (event) => {
      const g = event.target.closest("g.node");
      if (g) this.onToggle(g.dataset.id);
    });
    this.nodeLayer.addEventListener("pointerover", (event) => {
      const g = event.target.closest("g.node");
      if (g && this.highlight) this.highlightConnections(g.dataset.id);
    });
    this.nodeLayer.addEventListener("pointerout", () => this.highlightConnections(null));
  }

  highlightConnections(id) {
    for (const el of this.svg.querySelectorAll(".hl")) el.classList.remove("hl");
    if (id === null) return;
    for (const [child, path] of this.edges) {
      if (child === id || path.dataset.parent === id) {
        path.classList.add("hl");
        this.elements.get(child)?.classList.add("hl");
        this.elements.get(path.dataset.parent)?.classList.add("hl");
      }
    }
  }
}

// `base` classes plus those showing the node's state.
function stateClass(base, id, look) {
  const code = look.code(id);
  const status = code & 7;
  let cls = base + (status ? ` s${status}` : " never");
  if (code & 8) cls += " fresh";
  if (look.active.has(id)) cls += " active";
  else if (look.inside.has(id)) cls += " inside-active";
  if (look.hooked.has(id)) cls += " hooked";
  if (look.pausedAt === id) cls += " paused";
  return cls;
}

function displayLabel(node, folded) {
  let label = node.label || node.name || node.id;
  if (label.length > MAX_LABEL) label = `${label.slice(0, MAX_LABEL - 1)}…`;
  if (folded) label += ` ▸ +${countBelow(node)}`;
  return label;
}

export function countBelow(node) {
  let count = 0;
  const stack = [...node.children];
  while (stack.length) {
    const next = stack.pop();
    count += 1;
    stack.push(...next.children);
  }
  return count;
}

export function escapeHtml(text) {
  return String(text).replace(/[&<>"']/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" })[c]);
}
