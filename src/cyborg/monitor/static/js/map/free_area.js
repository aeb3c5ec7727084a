// The part of the map that its own controls leave free: Fit shows the whole map there, so that
// the toolbar (Fit, Follow, Layers, ⤢), the actions' bar, STOP and any warning or banner laid
// over the map never hide a goal, a dock or a robot that they act on.
//
// The controls are the map panel's children laid over the canvas (HTML over it, in
// index.html) that take clicks. What lets clicks through (pointer-events: none) is no control
// but may hold some: the actions' bar stands for its buttons, so the map may show between and
// beside them; the scale and the pointer's coordinates, the status line, the actions' log and
// tooltips cover nothing. The joystick comes and goes with Drive and is left out too: the map
// does not jump when it shows.
//
// freeRect picks, among the rectangles whose edges are the canvas's or a control's, the one
// free of every control that shows the map largest: a tall map takes the band between the
// toolbar and the bottom bar, a wide one may take the side beside STOP.

const PASSING_IDS = new Set(["map-canvas", "map-static", "map-joystick"]);

// The elements that cover the map's canvas (shown or not: a hidden one covers nothing).
function coveringElements(root) {
  const found = [];
  const visit = (parent) => {
    for (const element of parent.children) {
      if (PASSING_IDS.has(element.id)) continue;
      if (getComputedStyle(element).pointerEvents === "none") visit(element);
      else found.push(element);
    }
  };
  visit(root);
  return found;
}

// The boxes of the shown covering elements, [x0, y0, x1, y1] in CSS px on `canvas`.
export function coveringBoxes(root, canvas) {
  const origin = canvas.getBoundingClientRect();
  const boxes = [];
  for (const element of coveringElements(root)) {
    const box = element.getBoundingClientRect();
    if (box.width <= 0 || box.height <= 0) continue;
    boxes.push([box.left - origin.left, box.top - origin.top, box.right - origin.left, box.bottom - origin.top]);
  }
  return boxes;
}

// The free rectangle {x0, y0, x1, y1} of a `width` × `height` canvas under `boxes` that
// `score(w, h)` rates highest (the scale a fit would reach there; ties go to the larger area);
// the whole canvas when nothing covers it or no free rectangle scores above 0.
export function freeRect(width, height, boxes, score) {
  const whole = { x0: 0, y0: 0, x1: width, y1: height };
  const inside = boxes
    .map(([x0, y0, x1, y1]) => [Math.max(0, x0), Math.max(0, y0), Math.min(width, x1), Math.min(height, y1)])
    .filter(([x0, y0, x1, y1]) => x1 > x0 && y1 > y0);
  if (!inside.length) return whole;
  const lefts = [0, ...inside.map((b) => b[2])], rights = [width, ...inside.map((b) => b[0])];
  const tops = [0, ...inside.map((b) => b[3])], bottoms = [height, ...inside.map((b) => b[1])];
  let best = null, bestScore = 0, bestArea = 0;
  for (const x0 of lefts) {
    for (const x1 of rights) {
      if (x1 <= x0) continue;
      for (const y0 of tops) {
        for (const y1 of bottoms) {
          if (y1 <= y0) continue;
          const rated = score(x1 - x0, y1 - y0), area = (x1 - x0) * (y1 - y0);
          if (rated < bestScore - 1e-9 || (rated < bestScore + 1e-9 && area <= bestArea)) continue;
          if (inside.some((b) => b[0] < x1 && x0 < b[2] && b[1] < y1 && y0 < b[3])) continue;
          best = { x0, y0, x1, y1 };
          bestScore = rated;
          bestArea = area;
        }
      }
    }
  }
  return best ?? whole;
}
