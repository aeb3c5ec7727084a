// Where the map is on screen: world coordinates (metres, y up, as ROS and ARNL have them) to
// canvas pixels (CSS px, y down) and back, and the gestures that move the view.
//
// The view is a centre (cx, cy) in metres and a scale in pixels per metre:
//   screen x = width / 2 + (x - cx) · scale
//   screen y = height / 2 - (y - cy) · scale      (the minus flips y up into y down)
// Zooming "about the cursor" keeps the world point under the cursor where it is: zoom, then
// move the centre by however far that point drifted.
//
// Gestures (pointer events, so mouse, pen and touch alike): the wheel zooms about the cursor,
// one pointer drags to pan, two pointers pinch (zoom about their midpoint, pan with it).
// Every change bumps `version`, which tells the drawing that the view moved.

export const MIN_SCALE = 0.2; // px per m: 5 m a pixel
export const MAX_SCALE = 2000; // px per m: 0.5 mm a pixel
const FIT_MARGIN = 16; // px between a fitted map and the edge of where it is shown

export class ViewTransform {
  constructor() {
    this.cx = 0;
    this.cy = 0;
    this.scale = 20;
    this.width = 0;
    this.height = 0;
    this.version = 0;
  }

  toScreen(x, y) {
    return [this.width / 2 + (x - this.cx) * this.scale, this.height / 2 - (y - this.cy) * this.scale];
  }

  toWorld(sx, sy) {
    return [this.cx + (sx - this.width / 2) / this.scale, this.cy - (sy - this.height / 2) / this.scale];
  }

  // The world rectangle on screen, {x0, y0, x1, y1} in metres.
  visible() {
    const [x0, y1] = this.toWorld(0, 0);
    const [x1, y0] = this.toWorld(this.width, this.height);
    return { x0, y0, x1, y1 };
  }

  snapshot() {
    return { cx: this.cx, cy: this.cy, scale: this.scale, width: this.width, height: this.height };
  }

  resize(width, height) {
    if (width === this.width && height === this.height) return false;
    this.width = width;
    this.height = height;
    this.changed();
    return true;
  }

  // Zoom by `factor` keeping the world point under (sx, sy) in place.
  zoomAbout(factor, sx, sy) {
    const scale = Math.min(MAX_SCALE, Math.max(MIN_SCALE, this.scale * factor));
    if (scale === this.scale) return;
    const [wx, wy] = this.toWorld(sx, sy);
    this.scale = scale;
    const [ax, ay] = this.toWorld(sx, sy);
    this.cx += wx - ax;
    this.cy += wy - ay;
    this.changed();
  }

  // Move the picture by (dx, dy) screen pixels (the world moves with the pointer).
  panBy(dx, dy) {
    if (!dx && !dy) return;
    this.cx -= dx / this.scale;
    this.cy += dy / this.scale;
    this.changed();
  }

  centerOn(x, y) {
    if (x === this.cx && y === this.cy) return;
    this.cx = x;
    this.cy = y;
    this.changed();
  }

  // The scale (px per m) at which `bounds` ({x0, y0, x1, y1}, m) fill `width` × `height` px
  // less a margin of `margin` px all round (unclamped).
  static fitScale(bounds, width, height, margin = FIT_MARGIN) {
    const w = Math.max(bounds.x1 - bounds.x0, 0.5), h = Math.max(bounds.y1 - bounds.y0, 0.5);
    const room = (size) => Math.max(size - 2 * margin, 1);
    return Math.min(room(width) / w, room(height) / h);
  }

  // Show the whole of `bounds` ({x0, y0, x1, y1}, m) with a margin of FIT_MARGIN px, in the
  // middle of `area` ({x0, y0, x1, y1}, px on the canvas; the whole canvas by default).
  fit(bounds, area = { x0: 0, y0: 0, x1: this.width, y1: this.height }) {
    if (!this.width || !this.height || !bounds) return;
    const scale = ViewTransform.fitScale(bounds, area.x1 - area.x0, area.y1 - area.y0);
    this.scale = Math.min(MAX_SCALE, Math.max(MIN_SCALE, scale));
    // the bounds' middle on the area's middle
    this.cx = (bounds.x0 + bounds.x1) / 2 - ((area.x0 + area.x1) / 2 - this.width / 2) / this.scale;
    this.cy = (bounds.y0 + bounds.y1) / 2 + ((area.y0 + area.y1) / 2 - this.height / 2) / this.scale;
    this.changed();
  }

  changed() {
    this.version += 1;
  }

  // Wheel, drag and pinch on `element`. `onUser` hears each gesture that moved the view (the
  // panel turns "follow" off on a pan); `onCursor(sx, sy)` the pointer's position, or null.
  // `claim(event)`, when given, may take a press for itself (a tool's drag): the view then
  // leaves that pointer alone.
  attach(element, { onChange, onUser, onCursor, claim }) {
    const local = (event) => {
      const box = element.getBoundingClientRect();
      return [event.clientX - box.left, event.clientY - box.top];
    };
    element.addEventListener("wheel", (event) => {
      event.preventDefault();
      // Lines and pages (Firefox, some mice) are made pixels; trackpads send pixels already.
      const unit = event.deltaMode === 1 ? 16 : event.deltaMode === 2 ? this.height : 1;
      const [sx, sy] = local(event);
      this.zoomAbout(Math.exp(-event.deltaY * unit * 0.0015), sx, sy);
      onUser("zoom");
      onChange();
    }, { passive: false });

    const pointers = new Map(); // pointerId -> [sx, sy]
    let pinch = null; // {distance, mid} of the two pointers at the last move
    const twoFingers = () => {
      const [[ax, ay], [bx, by]] = [...pointers.values()];
      return { distance: Math.hypot(bx - ax, by - ay), mid: [(ax + bx) / 2, (ay + by) / 2] };
    };
    element.addEventListener("pointerdown", (event) => {
      if (event.button !== 0 && event.pointerType === "mouse") return;
      if (claim && claim(event)) return;
      try {
        element.setPointerCapture(event.pointerId); // keep the drag when the pointer leaves
      } catch {
        // a pointer the browser does not know (a synthetic event): drag without capture
      }
      pointers.set(event.pointerId, local(event));
      pinch = pointers.size === 2 ? twoFingers() : null;
      element.classList.add("dragging");
    });
    element.addEventListener("pointermove", (event) => {
      const at = local(event);
      onCursor(at[0], at[1]);
      const before = pointers.get(event.pointerId);
      if (!before) return;
      pointers.set(event.pointerId, at);
      if (pointers.size === 1) {
        this.panBy(at[0] - before[0], at[1] - before[1]);
        onUser("pan");
      } else if (pointers.size === 2 && pinch) {
        const now = twoFingers();
        this.panBy(now.mid[0] - pinch.mid[0], now.mid[1] - pinch.mid[1]);
        if (pinch.distance > 0 && now.distance > 0) this.zoomAbout(now.distance / pinch.distance, now.mid[0], now.mid[1]);
        pinch = now;
        onUser("pinch");
      }
      onChange();
    });
    const release = (event) => {
      pointers.delete(event.pointerId);
      pinch = pointers.size === 2 ? twoFingers() : null;
      if (!pointers.size) element.classList.remove("dragging");
    };
    element.addEventListener("pointerup", release);
    element.addEventListener("pointercancel", release);
    element.addEventListener("pointerleave", (event) => {
      if (event.pointerType === "mouse") onCursor(null, null);
    });
  }
}
