// When to redraw the static layers, and where: in the static worker when it can draw on an
// OffscreenCanvas, else on the page's main thread with the same drawing code.
//
// The bitmap covers the view plus a margin (a quarter of the view on each side), at the
// view's scale. Between renders the page blits the last bitmap shifted and scaled to the
// current view (moving_draw.js): a 0.6 ms drawImage instead of a 11–23 ms rasterisation. A new
// render is asked for only when the bitmap no longer serves: another scale (zoom), another
// device pixel ratio, other layers (not the labels: they are placed each frame, labels.js),
// another map, or a pan past the margin. At most one render is in flight; whatever the view
// did meanwhile is caught up when it returns.

import { drawStatic } from "./static_draw.js";

const MARGIN = 0.25; // of the view's width and height, on each side
const MAX_DEVICE_PIXELS = 12e6; // a bigger bitmap drops its margin
const WORKER_START_MS = 3000;

export class StaticLayer {
  // `onBitmap()` is called when a new bitmap is ready to be shown. `mainThread`: draw on the
  // page even where a worker could (the `?map_worker=0` switch, for comparison and tests).
  constructor({ onBitmap, mainThread = false }) {
    this.onBitmap = onBitmap;
    this.map = null;
    this.mapId = 0;
    this.current = null; // {bitmap, region, layersKey, mapId, drawn, serial}
    this.serial = 0; // counts the bitmaps shown
    this.inFlight = false;
    this.n = 0;
    this.renders = 0;
    this.where = "main thread";
    this.worker = null;
    this.workerState = "none"; // none | starting | ready
    if (!mainThread && typeof Worker !== "undefined" && typeof OffscreenCanvas !== "undefined") this.startWorker();
  }

  startWorker() {
    try {
      this.worker = new Worker(new URL("./static_worker.js", import.meta.url), { type: "module" });
    } catch {
      return;
    }
    this.workerState = "starting";
    const fallBack = () => {
      if (!this.worker) return;
      this.worker.terminate();
      this.worker = null;
      this.workerState = "none";
      this.where = "main thread";
      this.inFlight = false;
      this.onBitmap(); // draw again, here
    };
    const timer = setTimeout(fallBack, WORKER_START_MS);
    this.worker.onerror = (event) => {
      event.preventDefault(); // handled: no console error, the page draws instead
      clearTimeout(timer);
      fallBack();
    };
    this.worker.onmessage = (event) => {
      const message = event.data;
      if (message.t === "ready") {
        clearTimeout(timer);
        this.workerState = "ready";
        this.where = "worker";
        if (this.map) this.sendMap();
        this.onBitmap();
      } else if (message.t === "failed") {
        clearTimeout(timer);
        fallBack();
      } else if (message.t === "bitmap") {
        this.inFlight = false;
        if (message.id !== this.mapId) {
          message.bitmap.close();
          this.onBitmap();
          return;
        }
        this.show(message.bitmap, message.region, message.layers, message.drawn);
      }
    };
  }

  setMap(map) {
    this.map = map;
    this.mapId += 1;
    if (this.current && this.current.bitmap.close) this.current.bitmap.close();
    this.current = null;
    if (this.workerState === "ready") this.sendMap();
  }

  sendMap() {
    const { lines, points, objects, resolution } = this.map;
    // A structured clone: the worker gets its own copy of the floats (about 0.5 MB for
    // columbia, ~1 ms), and the page keeps its views for hit tests and fallbacks.
    this.worker.postMessage({ t: "data", id: this.mapId, map: { lines, points, objects, resolution } });
  }

  // Asks for a render if the current bitmap does not serve `view` (a ViewTransform snapshot)
  // at `dpr` with `layers`. Returns true when a bitmap that serves is there now.
  update(view, dpr, layers) {
    if (!this.map || !view.width || !view.height) return false;
    const layersKey = keyOf(layers);
    if (this.covers(view, dpr, layersKey)) return true;
    if (this.inFlight || this.workerState === "starting") return false;
    const region = regionFor(view, dpr);
    const wanted = { points: !!layers.points, walls: !!layers.walls, forbidden: !!layers.forbidden, goals: !!layers.goals };
    this.renders += 1;
    if (this.workerState === "ready") {
      this.inFlight = true;
      this.n += 1;
      this.worker.postMessage({ t: "render", id: this.mapId, n: this.n, region, layers: wanted });
      return false;
    }
    // On the main thread: draw now, into a canvas kept for the purpose.
    if (!this.canvas) this.canvas = document.createElement("canvas");
    const canvas = this.canvas;
    canvas.width = Math.max(1, Math.round(region.width * dpr));
    canvas.height = Math.max(1, Math.round(region.height * dpr));
    const drawn = drawStatic(canvas.getContext("2d"), this.map, region, wanted);
    this.current = { bitmap: canvas, region, layersKey, mapId: this.mapId, drawn, serial: ++this.serial };
    return true;
  }

  show(bitmap, region, layers, drawn) {
    if (this.current && this.current.bitmap.close) this.current.bitmap.close();
    this.current = { bitmap, region, layersKey: keyOf(layers), mapId: this.mapId, drawn, serial: ++this.serial };
    this.onBitmap();
  }

  // Whether the current bitmap is of this map, scale, dpr and layers, and holds the whole view.
  covers(view, dpr, layersKey) {
    const c = this.current;
    if (!c || c.mapId !== this.mapId || c.layersKey !== layersKey) return false;
    const r = c.region;
    if (r.dpr !== dpr || Math.abs(r.scale - view.scale) > 1e-9 * view.scale) return false;
    const halfW = view.width / 2 / view.scale, halfH = view.height / 2 / view.scale;
    const x1 = r.x0 + r.width / r.scale, y0 = r.y1 - r.height / r.scale;
    return view.cx - halfW >= r.x0 && view.cx + halfW <= x1 && view.cy - halfH >= y0 && view.cy + halfH <= r.y1;
  }

  // The bitmap's placement in the current view: drawImage(bitmap, x, y, w, h) in CSS px.
  placement(view) {
    const c = this.current;
    if (!c) return null;
    const r = c.region;
    const zoom = view.scale / r.scale;
    return {
      serial: c.serial,
      bitmap: c.bitmap,
      x: view.width / 2 + (r.x0 - view.cx) * view.scale,
      y: view.height / 2 - (r.y1 - view.cy) * view.scale,
      w: r.width * zoom,
      h: r.height * zoom,
    };
  }
}

function keyOf(layers) {
  return ["points", "walls", "forbidden", "goals"].map((name) => (layers[name] ? 1 : 0)).join("");
}

// The view plus the margin, centred on the view's centre; smaller on huge screens.
function regionFor(view, dpr) {
  let grow = 1 + 2 * MARGIN;
  if (view.width * view.height * grow * grow * dpr * dpr > MAX_DEVICE_PIXELS) grow = 1;
  const width = Math.ceil(view.width * grow), height = Math.ceil(view.height * grow);
  return {
    x0: view.cx - width / 2 / view.scale,
    y1: view.cy + height / 2 / view.scale,
    width, height, scale: view.scale, dpr,
  };
}
