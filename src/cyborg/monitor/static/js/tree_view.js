// Draws a behaviour tree top-down in SVG and keeps it coloured by status.
//
// Layout is d3-hierarchy's tidy tree with a separation that knows each box's width. What is
// drawn follows rqt_bt's Draw depth (subtrees nested deeper than N are folded into one node)
// plus per-node folding (double-click), and the running path is always unfolded unless the
// user folded it by hand. Status updates only change class names, so a 1,000-node tree takes
// a live stream without redrawing.

import { hierarchy, tree as tidyTree } from "../vendor/d3-hierarchy.min.mjs";

const BOX_HEIGHT = 28;
const ROW_GAP = 46;
const CHAR_PX = 7;
const PAD_PX = 18;
const SIBLING_GAP = 14;
const MAX_LABEL = 40;
const FAR_SCALE = 0.35;
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
    this.edges = new Map(); // child id -> <path>
    this.highlight = true;
    this.size = { width: 0, height: 0 };
    new ResizeObserver(([entry]) => {
      this.size = { width: entry.contentRect.width, height: entry.contentRect.height };
    }).observe(svg);
    this.listen();
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
    const layoutRoot = hierarchy(root, (node) => (isOpen(node) ? node.children : null));
    layoutRoot.each((d) => {
      const label = displayLabel(d.data, !isOpen(d.data) && d.data.children.length > 0);
      d.label = label;
      d.width = label.length * CHAR_PX + PAD_PX;
    });
    tidyTree()
      .nodeSize([1, BOX_HEIGHT + ROW_GAP])
      .separation((a, b) => (a.width + b.width) / 2 + (a.parent === b.parent ? SIBLING_GAP : SIBLING_GAP * 2))(layoutRoot);
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
    return nodes.length;
  }

  clear() {
    this.edgeLayer.innerHTML = "";
    this.nodeLayer.innerHTML = "";
    this.elements = new Map();
    this.edges = new Map();
    this.badges = new Map();
    this.layoutRoot = null;
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
  }

  // The view's size, from the DOM (a layout if one is due); the ResizeObserver keeps it after.
  measure() {
    const { width, height } = this.svg.getBoundingClientRect();
    this.size = { width, height };
  }

  fit() {
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
    this.apply();
  }

  centerOn(id) {
    const d = this.layoutRoot && this.layoutRoot.descendants().find((n) => n.data.id === id);
    if (!d) return;
    const box = this.svg.getBoundingClientRect();
    const k = Math.max(this.transform.k, 0.8);
    this.transform = { k, x: box.width / 2 - d.x * k, y: box.height / 3 - d.y * k };
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
      this.apply();
      this.onUserZoom();
    }, { passive: false });
    let drag = null;
    svg.addEventListener("pointerdown", (event) => {
      if (event.target.closest("g.node")) return;
      drag = { x: event.clientX, y: event.clientY, t: { ...this.transform } };
      svg.classList.add("dragging");
    });
    window.addEventListener("pointermove", (event) => {
      if (!drag) return;
      this.transform = { ...drag.t, x: drag.t.x + event.clientX - drag.x, y: drag.t.y + event.clientY - drag.y };
      this.apply();
    });
    window.addEventListener("pointerup", () => {
      if (drag && (this.transform.x !== drag.t.x || this.transform.y !== drag.t.y)) this.onUserZoom();
      drag = null;
      svg.classList.remove("dragging");
    });
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
