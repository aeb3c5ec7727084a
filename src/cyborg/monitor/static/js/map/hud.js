// The map's heads-up display, in HTML over the canvas: scale bar, cursor coordinates, layer
// toggles, warnings and the "no map yet" line. HTML rather than canvas, so it is crisp, takes
// clicks, and costs nothing per frame: each part is rewritten only when what it shows changes.
//
// Layer choices are kept in localStorage, so a reload (or the next visit) shows the same. A
// layer nobody chose may change its default while the page runs (autoLayer): "Detected objects"
// goes off once a tracker's objects come, which show the same things better placed.

export const LAYERS = [
  ["walls", "Walls"], ["points", "Scanned points"], ["forbidden", "Forbidden lines and areas"],
  ["goals", "Goals, docks, home"], ["paths", "Paths"], ["laser", "Laser"],
  ["tracked", "Tracked objects"], ["detections", "Detected objects"],
  ["robots", "Robots"], ["labels", "Labels"],
];
const STORE = "cyborg-monitor-map-layers";
const SCALE_PX = 100; // the scale bar's length is 1, 2 or 5 × 10ⁿ m, near this many pixels

export class Hud {
  // `root`: the #map-view element. `onLayers(layers)` hears a toggle; `onFit()` the Fit button;
  // `onFollow(on)` the Follow box.
  constructor(root, { onLayers, onFit, onFollow }) {
    const $ = (selector) => root.querySelector(selector);
    this.status = $("#map-status");
    this.scaleBar = $("#map-scale .bar");
    this.scaleLabel = $("#map-scale .label");
    this.cursor = $("#map-cursor");
    this.warningBox = $("#map-warnings");
    this.warningCount = $("#map-warning-count");
    this.warningList = $("#map-warning-list");
    this.follow = $("#map-follow");
    [this.layers, this.chosen] = loadLayers();
    this.onLayers = onLayers;
    this.boxes = new Map(); // layer name -> its checkbox
    this.shown = { scale: null, warnings: "", status: null };
    const menu = $("#map-layer-list");
    for (const [name, label] of LAYERS) {
      const row = document.createElement("label");
      const box = document.createElement("input");
      box.type = "checkbox";
      box.dataset.layer = name;
      box.checked = this.layers[name];
      this.boxes.set(name, box);
      box.addEventListener("change", () => {
        this.layers = { ...this.layers, [name]: box.checked };
        this.chosen.add(name);
        try {
          const saved = Object.fromEntries([...this.chosen].map((chosen) => [chosen, this.layers[chosen]]));
          localStorage.setItem(STORE, JSON.stringify(saved));
        } catch {
          // storage full or refused (private windows): the choice lasts this page only
        }
        onLayers(this.layers);
      });
      row.append(box, ` ${label}`);
      menu.append(row);
    }
    $("#map-fit").addEventListener("click", () => onFit());
    this.follow.addEventListener("change", () => onFollow(this.follow.checked));
  }

  // Switches layer `name` on or off by default, unless the user chose it (in Layers, now or
  // on an earlier visit).
  autoLayer(name, on) {
    if (this.chosen.has(name) || this.layers[name] === on) return;
    this.layers = { ...this.layers, [name]: on };
    this.boxes.get(name).checked = on;
    this.onLayers(this.layers);
  }

  setFollow(on) {
    this.follow.checked = on;
  }

  // "no map yet", "loading columbia.map …", an error, or "" once the map is drawn.
  showStatus(text) {
    if (text === this.shown.status) return;
    this.shown.status = text;
    this.status.textContent = text;
    this.status.hidden = !text;
  }

  // The bar for `scale` px per m.
  showScale(scale) {
    if (scale === this.shown.scale) return;
    this.shown.scale = scale;
    const metres = niceLength(SCALE_PX / scale);
    this.scaleBar.style.width = `${Math.round(metres * scale)}px`;
    this.scaleLabel.textContent = lengthText(metres);
  }

  // Where the pointer is in the world, in metres with 2 decimals; null: off the map.
  showCursor(xy) {
    this.cursor.textContent = xy ? `x ${xy[0].toFixed(2)} m  y ${xy[1].toFixed(2)} m` : "";
  }

  // The model's warnings, newest first, each with how often it came.
  showWarnings(warnings) {
    const key = warnings.map((w) => `${w.at}:${w.count}`).join();
    if (key === this.shown.warnings) return;
    this.shown.warnings = key;
    this.warningBox.hidden = !warnings.length;
    this.warningCount.textContent = String(warnings.length);
    this.warningList.replaceChildren(...warnings.map((w) => {
      const item = document.createElement("li");
      item.textContent = `${w.ns ? `${w.ns} ` : ""}${w.message}${w.count > 1 ? ` (×${w.count})` : ""}`;
      item.title = `${w.kind}, last at ${new Date(w.at).toLocaleTimeString()}`;
      return item;
    }));
  }
}

// [layers, the names the user chose]: every layer on but those chosen off.
function loadLayers() {
  const layers = Object.fromEntries(LAYERS.map(([name]) => [name, true]));
  const chosen = new Set();
  try {
    const saved = JSON.parse(localStorage.getItem(STORE) || "{}");
    for (const [name] of LAYERS) {
      if (typeof saved[name] !== "boolean") continue;
      layers[name] = saved[name];
      chosen.add(name);
    }
  } catch {
    // nothing saved, or not readable: all layers on
  }
  return [layers, chosen];
}

// The 1, 2 or 5 × 10ⁿ m closest to `metres` (on a log scale).
export function niceLength(metres) {
  const power = 10 ** Math.floor(Math.log10(metres));
  let best = power;
  for (const step of [1, 2, 5, 10]) {
    if (Math.abs(Math.log(step * power / metres)) < Math.abs(Math.log(best / metres))) best = step * power;
  }
  return best;
}

function lengthText(metres) {
  if (metres >= 1) return `${Math.round(metres)} m`;
  if (metres >= 0.01) return `${Math.round(metres * 100)} cm`;
  return `${Math.round(metres * 1000 * 10) / 10} mm`;
}
