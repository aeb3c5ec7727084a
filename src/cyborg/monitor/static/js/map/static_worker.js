// The static layers, drawn off the page's main thread (a module worker started by
// static_layer.js). Rasterising columbia's 63k points takes 11–23 ms; here that time is not
// taken from the page's frames, so panning and the robots stay smooth while it draws.
//
// Messages from the page:
//   {t: "data", id, map: {lines, points, objects, resolution}}   the map, once per map
//   {t: "render", id, n, region, layers}   draw; `id` names the map, `n` the request
// Answers:
//   {t: "ready"}   once this worker can draw (OffscreenCanvas with a 2D context)
//   {t: "bitmap", id, n, region, layers, bitmap, drawn}   the bitmap is transferred, not copied
//   {t: "failed", message}   this worker cannot draw: the page draws on its main thread instead

import { drawStatic } from "./static_draw.js";

let map = null;
let mapId = null;
let canvas = null;
let ctx = null;

try {
  canvas = new OffscreenCanvas(1, 1);
  ctx = canvas.getContext("2d");
  if (!ctx) throw new Error("no 2D context on an OffscreenCanvas");
  self.postMessage({ t: "ready" });
} catch (error) {
  self.postMessage({ t: "failed", message: String(error && error.message ? error.message : error) });
}

self.onmessage = (event) => {
  const message = event.data;
  try {
    if (message.t === "data") {
      map = message.map;
      mapId = message.id;
    } else if (message.t === "render" && ctx && map && message.id === mapId) {
      const { region } = message;
      const width = Math.max(1, Math.round(region.width * region.dpr));
      const height = Math.max(1, Math.round(region.height * region.dpr));
      // Setting the size clears the canvas; skip it when the size is the same.
      if (canvas.width !== width) canvas.width = width;
      if (canvas.height !== height) canvas.height = height;
      const drawn = drawStatic(ctx, map, region, message.layers);
      const bitmap = canvas.transferToImageBitmap();
      self.postMessage({ t: "bitmap", id: message.id, n: message.n, region, layers: message.layers, bitmap, drawn }, [bitmap]);
    }
  } catch (error) {
    self.postMessage({ t: "failed", message: String(error && error.message ? error.message : error) });
  }
};
