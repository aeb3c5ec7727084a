// What the map panel knows: the maps (decoded from the monitor's binary blobs), each robot's
// latest state, and the warnings to show. Messages are applied here; the drawing modules
// only read.
//
// Wire format (docs/monitor.md, "The map's data path"), from the monitor's WebSocket as JSON:
//   {t:"map_ref", ns, key, url, source, counts:{points, lines, objects}}
//       the robot `ns` is on the map `key`; its blob is at /api/map/{key} (immutable); key null:
//       the robot's map was refused (it has none to show now)
//   {t:"rs", ns, seq, p:[x, y, θ], sc?, st?, bat?, pid?, fp?, node?, goal?}
//       a robot's state: pose in m and rad; sc = {a0, da, mx, r:[mm], m?:[x, y, θ]} a laser
//       scan (a0, da in rad; mx range_max in mm; r: 0 = no return, -1 = invalid; m the laser's
//       mount on the robot, m and rad; none: the robot's centre); st the path state
//       (PLANNING_PATH, MOVING_TO_GOAL, REACHED_GOAL ...); bat = {pct, charging, dock};
//       pid the id of the path being followed; fp the footprint, x y ... in m in the robot's
//       frame, sent when it changed (kept until the next); node the label of the node running
//       in the robot's tree ("" for none) and goal = {name, p:[x, y, θ], h} the goal it drives
//       to (h: whether it turns to θ there; null for none), both sent when they changed
//   {t:"path", ns, id, xy:[x y ... in mm]}   the planned path (latched: paired with st, pid)
//   {t:"det", ns, id, d:[{label, score, p:[x, y]}]}   what the robot's detector saw last, placed
//       on the map by the monitor (m); shown for DETECTIONS_SHOWN_MS after it came
//   {t:"obj", ns, id, stamp, o:[{id, label, x, y, vx, vy, conf, age, seen}]}   what the robot's
//       tracker follows, on the map (read by tracked_objects.js); replaces the robot's list
//   {t:"robot_warn", ns, kind, message, count}   something the monitor refused or mended
//   {t:"robots", ..., map_robots:[{ns, tree, alive, map}]}   (app.js's message) which tree drives
//       which robot, and whether the robot is on the bus; read by MapPanel.pairRobots
// Old or missing fields are tolerated: bat.charge for bat.pct, a `robot` field in the robots
// list's tree entries for map_robots.
//
// The blob (parseMapBlob): 8 bytes "CYMAP\0" + u16 version 1, a u32 header length H, H bytes of
// JSON header {source, bounds:[x0, y0, x1, y1], resolution, counts:{lines, points, objects},
// objects:[{kind, category, name, description, pose:[x, y, θ], outline:[x y ...]}]} padded so
// that 12 + H is a multiple of 4, then 4·lines float32 (x1 y1 x2 y2, m) and 2·points float32
// (x y, m), little-endian. The floats are read in place: Float32Array views on the fetched
// buffer, no copy (unless the buffer is misaligned, which a well-formed blob never is).
//
// A message that fails to decode becomes a warning, never an exception that would stop the
// page: every message is applied inside try/catch.

import { colourOf } from "../robots.js";
import { readTracked } from "./tracked_objects.js";

export const CATEGORY = { OTHER: 0, GOAL: 1, GOAL_WITH_HEADING: 2, DOCK: 3, HOME: 4, FORBIDDEN_LINE: 5, FORBIDDEN_AREA: 6, SIM_OBSTACLE: 7 };
export { PALETTE } from "../robots.js";
// The Pioneer LX's 12-point outline (nav/footprint.py), until the robot tells its own.
export const DEFAULT_FOOTPRINT = Float32Array.from([
  0.32, 0.18, 0.29, 0.21, 0.26, 0.24, -0.26, 0.24, -0.29, 0.21, -0.32, 0.18,
  -0.32, -0.18, -0.29, -0.21, -0.26, -0.24, 0.26, -0.24, 0.29, -0.21, 0.32, -0.18]);
const MOVING = new Set(["PLANNING_PATH", "MOVING_TO_GOAL", "WAITING_FOR_PATH"]);
const MAGIC = [67, 89, 77, 65, 80, 0]; // "CYMAP\0"
const MAX_BEAMS = 8192;
const MAX_PATH_NUMBERS = 2 * 20000 + 2;
const MAX_WARNINGS = 50;
const MAX_DETECTIONS = 256;
export const DETECTIONS_SHOWN_MS = 3000; // a detector that stopped leaves nothing behind for long
const LITTLE_ENDIAN = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

// ------------------------------------------------------------------ the blob
export function parseMapBlob(buffer) {
  if (!(buffer instanceof ArrayBuffer)) throw new Error("map blob: not binary data");
  if (buffer.byteLength < 12) throw new Error(`map blob: ${buffer.byteLength} bytes, too short`);
  const head = new DataView(buffer);
  for (let i = 0; i < MAGIC.length; i++) {
    if (head.getUint8(i) !== MAGIC[i]) throw new Error("map blob: does not start with CYMAP");
  }
  const version = head.getUint16(6, true);
  if (version !== 1) throw new Error(`map blob: version ${version}, this page reads version 1`);
  const headerBytes = head.getUint32(8, true);
  if (12 + headerBytes > buffer.byteLength) throw new Error(`map blob: header of ${headerBytes} bytes runs past the end`);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 12, headerBytes)));
  if (!header || typeof header !== "object") throw new Error("map blob: the header is not a JSON object");
  const counts = header.counts || {};
  const nLines = count(counts.lines, "lines"), nPoints = count(counts.points, "points");
  const start = 12 + headerBytes;
  const expected = start + 16 * nLines + 8 * nPoints;
  if (expected !== buffer.byteLength) {
    throw new Error(`map blob: ${buffer.byteLength} bytes, but its header promises ${expected} (${nLines} lines, ${nPoints} points)`);
  }
  const lines = floats(buffer, start, 4 * nLines);
  const points = floats(buffer, start + 16 * nLines, 2 * nPoints);
  const warnings = [];
  const objects = [];
  for (const [index, raw] of (Array.isArray(header.objects) ? header.objects : []).entries()) {
    try {
      objects.push(mapObject(raw));
    } catch (error) {
      warnings.push(`map object ${index}: ${error.message}`);
    }
  }
  return {
    source: String(header.source ?? ""),
    resolution: Number.isFinite(header.resolution) ? header.resolution : 0,
    bounds: boundsOf(header.bounds, lines, points, objects),
    lines, points, objects, warnings,
  };
}

function count(value, name) {
  if (!Number.isInteger(value) || value < 0) throw new Error(`map blob: counts.${name} is not a count (${JSON.stringify(value)})`);
  return value;
}

// Zero-copy when aligned and little-endian (always, for a well-formed blob on a real machine).
function floats(buffer, offset, length) {
  if (LITTLE_ENDIAN && offset % 4 === 0) return new Float32Array(buffer, offset, length);
  const view = new DataView(buffer, offset, length * 4);
  const copy = new Float32Array(length);
  for (let i = 0; i < length; i++) copy[i] = view.getFloat32(4 * i, true);
  return copy;
}

function mapObject(raw) {
  if (!raw || typeof raw !== "object") throw new Error("not an object");
  const pose = triple(raw.pose ?? [0, 0, 0], "pose");
  const outline = Array.isArray(raw.outline) ? raw.outline : [];
  if (outline.length % 2 || outline.some((v) => !Number.isFinite(v))) throw new Error("outline is not x y pairs of numbers");
  const category = Number.isInteger(raw.category) && raw.category >= 0 && raw.category <= 7 ? raw.category : CATEGORY.OTHER;
  return {
    kind: text(raw.kind), category, name: text(raw.name), description: text(raw.description),
    x: pose[0], y: pose[1], th: pose[2], outline: Float32Array.from(outline),
  };
}

// The header's bounds when they are four finite numbers, else computed from the geometry.
function boundsOf(given, lines, points, objects) {
  if (Array.isArray(given) && given.length === 4 && given.every(Number.isFinite) && given[2] >= given[0] && given[3] >= given[1]) {
    return { x0: given[0], y0: given[1], x1: given[2], y1: given[3] };
  }
  const box = { x0: Infinity, y0: Infinity, x1: -Infinity, y1: -Infinity };
  const add = (x, y) => {
    if (!Number.isFinite(x) || !Number.isFinite(y)) return;
    if (x < box.x0) box.x0 = x;
    if (x > box.x1) box.x1 = x;
    if (y < box.y0) box.y0 = y;
    if (y > box.y1) box.y1 = y;
  };
  for (const xy of [lines, points]) for (let i = 0; i < xy.length; i += 2) add(xy[i], xy[i + 1]);
  for (const item of objects) {
    add(item.x, item.y);
    for (let i = 0; i < item.outline.length; i += 2) add(item.outline[i], item.outline[i + 1]);
  }
  return box.x0 <= box.x1 ? box : { x0: -5, y0: -5, x1: 5, y1: 5 };
}

// ------------------------------------------------------------------ checks on messages
function finite(value, name) {
  if (typeof value !== "number" || !Number.isFinite(value)) throw new Error(`${name} is not a finite number (${short(value)})`);
  return value;
}

function triple(value, name) {
  if (!Array.isArray(value) || value.length !== 3) throw new Error(`${name} is not [x, y, θ] (${short(value)})`);
  return value.map((v, i) => finite(v, `${name}[${i}]`));
}

function text(value, limit = 200) {
  return value === undefined || value === null ? "" : String(value).slice(0, limit);
}

function namespace(message) {
  if (typeof message.ns !== "string" || !message.ns || message.ns.length > 200) throw new Error(`ns is not a namespace (${short(message.ns)})`);
  return message.ns;
}

function short(value) {
  const shown = JSON.stringify(value);
  return shown === undefined ? String(value) : shown.length > 40 ? `${shown.slice(0, 39)}…` : shown;
}

// ------------------------------------------------------------------ the model
export class MapModel {
  constructor() {
    this.maps = new Map(); // key -> parsed map
    this.refs = new Map(); // robot ns -> {key, url, source, counts}
    this.robots = new Map(); // robot ns -> state (see robot())
    this.warnings = []; // {ns, kind, message, count, at}, newest first
    this.alive = new Map(); // robot ns -> whether it is on the bus (the monitor's map_robots)
    this.version = 0; // bumped by every change the drawing should see
  }

  // Applies one message; returns its type when it was a map message (handled here, even when
  // it was malformed), null otherwise.
  receive(message) {
    const type = message && typeof message === "object" ? message.t : undefined;
    if (!["rs", "path", "det", "obj", "map_ref", "robot_warn"].includes(type)) return null;
    try {
      if (type === "rs") this.robotState(message);
      else if (type === "path") this.path(message);
      else if (type === "det") this.detections(message);
      else if (type === "obj") this.robot(namespace(message)).tracked = readTracked(message);
      else if (type === "map_ref") this.mapRef(message);
      else this.serverWarning(message);
      this.version += 1;
    } catch (error) {
      this.warn(typeof message.ns === "string" ? message.ns.slice(0, 200) : "", `bad ${type}`, `${type}: ${error.message}; ignored`);
    }
    return type;
  }

  // Adds or renews a warning; the same (ns, kind) is one row with a count.
  warn(ns, kind, message, count = null) {
    const row = this.warnings.find((w) => w.ns === ns && w.kind === kind);
    if (row) {
      row.message = message;
      row.count = count ?? row.count + 1;
      row.at = Date.now();
      this.warnings.splice(this.warnings.indexOf(row), 1);
      this.warnings.unshift(row);
    } else {
      this.warnings.unshift({ ns, kind, message, count: count ?? 1, at: Date.now() });
      this.warnings.length = Math.min(this.warnings.length, MAX_WARNINGS);
    }
    this.version += 1;
  }

  serverWarning(message) {
    const count = Number.isInteger(message.count) && message.count > 0 ? message.count : null;
    this.warn(text(message.ns), text(message.kind, 60) || "warning", text(message.message, 400), count);
  }

  robot(ns) {
    let robot = this.robots.get(ns);
    if (!robot) {
      robot = {
        ns, seq: null, pose: null, scan: null, scanCount: 0, mount: null, footprint: DEFAULT_FOOTPRINT, alive: this.alive.get(ns) ?? true,
        node: "", state: "", goal: null, battery: null, pathId: null, path: null, progress: null, colour: colourOf(ns),
        seen: null, // {at (ms), items: [{label, score, x, y}]}: the detector's objects
        tracked: null, // {at (ms), stamp, items}: the tracker's objects (tracked_objects.js)
      };
      this.robots.set(ns, robot);
    }
    return robot;
  }

  // Whether the robot `ns` is on the bus; kept for robots the page has not heard of yet (they
  // get no colour until they send something to draw).
  setAlive(ns, alive) {
    if (this.alive.get(ns) === alive) return;
    this.alive.set(ns, alive);
    if (this.alive.size > 64) this.alive.delete(this.alive.keys().next().value);
    const robot = this.robots.get(ns);
    if (robot) robot.alive = alive;
    this.version += 1;
  }

  robotState(message) {
    const ns = namespace(message);
    const seq = finite(message.seq, "seq");
    const pose = triple(message.p, "p");
    const known = this.robots.get(ns);
    // Deltas may arrive twice around a resync; a big jump back is a restarted monitor.
    if (known && known.seq !== null && seq <= known.seq && known.seq - seq < 1000) return;
    const scan = message.sc === undefined || message.sc === null ? null : scanEndpoints(message.sc, pose);
    const footprint = message.fp === undefined ? null : outline(message.fp, "fp");
    const goal = message.goal === undefined || message.goal === null ? null : goalOf(message.goal);
    const robot = this.robot(ns);
    robot.seq = seq;
    robot.pose = { x: pose[0], y: pose[1], th: pose[2] };
    if (scan) [robot.scan, robot.scanCount, robot.mount] = scan;
    else if (message.sc === null) robot.scanCount = 0;
    if (footprint) robot.footprint = footprint;
    if ("node" in message) robot.node = text(message.node);
    if ("st" in message) robot.state = text(message.st, 40);
    if ("goal" in message) robot.goal = goal;
    if ("bat" in message) robot.battery = batteryOf(message.bat);
    if ("pid" in message) robot.pathId = message.pid;
    if (robot.path) robot.progress = pathProgress(robot.path, robot.pose, robot.progress);
  }

  path(message) {
    const ns = namespace(message);
    const xy = message.xy;
    if (!Array.isArray(xy) || xy.length % 2) throw new Error("xy is not a list of x y pairs");
    if (xy.length > MAX_PATH_NUMBERS) throw new Error(`${xy.length / 2} poses, more than the 20,000 drawn`);
    const points = new Float32Array(xy.length);
    for (let i = 0; i < xy.length; i++) points[i] = finite(xy[i], `xy[${i}]`) / 1000;
    const cumulative = new Float32Array(xy.length / 2);
    for (let i = 1; i < cumulative.length; i++) {
      cumulative[i] = cumulative[i - 1] + Math.hypot(points[2 * i] - points[2 * i - 2], points[2 * i + 1] - points[2 * i - 1]);
    }
    const robot = this.robot(ns);
    robot.path = { id: message.id ?? null, xy: points, cumulative };
    robot.progress = robot.pose ? pathProgress(robot.path, robot.pose, null) : null;
  }

  detections(message) {
    const ns = namespace(message);
    const items = message.d;
    if (!Array.isArray(items)) throw new Error("d is not a list of objects");
    if (items.length > MAX_DETECTIONS) throw new Error(`${items.length} objects, more than the ${MAX_DETECTIONS} drawn`);
    const seen = items.map((item, i) => {
      if (!item || typeof item !== "object") throw new Error(`d[${i}] is not an object`);
      if (!Array.isArray(item.p) || item.p.length !== 2) throw new Error(`d[${i}].p is not [x, y] (${short(item.p)})`);
      return { label: text(item.label, 60), score: Number.isFinite(item.score) ? item.score : null, x: finite(item.p[0], `d[${i}].p[0]`), y: finite(item.p[1], `d[${i}].p[1]`) };
    });
    this.robot(ns).seen = { at: Date.now(), items: seen };
  }

  // The detector's objects still worth showing for `robot` (none once they are old).
  seenNow(robot, now = Date.now()) {
    return robot.seen && now - robot.seen.at < DETECTIONS_SHOWN_MS ? robot.seen.items : [];
  }

  mapRef(message) {
    const ns = namespace(message);
    if (message.key === null) {
      this.refs.delete(ns); // the robot's new map was refused: it is on no map the page has
      this.robot(ns);
      return;
    }
    if (typeof message.key !== "string" || !/^[0-9a-f]{8,64}$/.test(message.key)) throw new Error(`key is not a map key (${short(message.key)})`);
    // The blob comes from this monitor only: /api/map/<key>, whatever the message says.
    const url = `/api/map/${message.key}`;
    const counts = message.counts && typeof message.counts === "object" ? message.counts : {};
    this.refs.set(ns, { key: message.key, url, source: text(message.source), counts });
    this.robot(ns);
  }

  // Whether the robot's path and goal are current: its path state says it is on its way (or
  // says nothing), and the path is the one it follows (or no id is given).
  travelling(robot) {
    return !robot.state || MOVING.has(robot.state);
  }

  pathShown(robot) {
    return robot.path !== null && this.travelling(robot) && (robot.pathId === null || robot.pathId === undefined || robot.pathId === robot.path.id);
  }
}

// The scan's hit points in the map frame, through the laser's mount: [Float32Array, count,
// the mount [x, y, θ] or null when the monitor gave none].
function scanEndpoints(scan, pose) {
  if (!scan || typeof scan !== "object") throw new Error("sc is not an object");
  const a0 = finite(scan.a0, "sc.a0"), da = finite(scan.da, "sc.da");
  const ranges = scan.r;
  if (!Array.isArray(ranges)) throw new Error("sc.r is not a list");
  if (ranges.length > MAX_BEAMS) throw new Error(`sc.r has ${ranges.length} beams, more than ${MAX_BEAMS}`);
  const given = scan.m !== undefined && scan.m !== null;
  const mount = given ? triple(scan.m, "sc.m") : [0, 0, 0];
  const [x, y, th] = pose;
  const cos = Math.cos(th), sin = Math.sin(th);
  const lx = x + cos * mount[0] - sin * mount[1], ly = y + sin * mount[0] + cos * mount[1];
  const out = new Float32Array(2 * ranges.length);
  let n = 0;
  for (let i = 0; i < ranges.length; i++) {
    const r = ranges[i];
    if (typeof r !== "number") throw new Error(`sc.r[${i}] is not a number (${short(r)})`);
    if (!(r > 0)) continue; // 0: no return, -1: invalid
    const angle = th + mount[2] + a0 + i * da, metres = r / 1000;
    out[2 * n] = lx + metres * Math.cos(angle);
    out[2 * n + 1] = ly + metres * Math.sin(angle);
    n += 1;
  }
  return [out, n, given ? mount : null];
}

function outline(value, name) {
  if (!Array.isArray(value) || value.length < 6 || value.length > 512 || value.length % 2) throw new Error(`${name} is not an outline of x y pairs`);
  return Float32Array.from(value, (v, i) => finite(v, `${name}[${i}]`));
}

// {pct, charging, dock} (pct a finite 0-100 or null); `charge` is the old name of `pct`.
function batteryOf(bat) {
  if (!bat || typeof bat !== "object") return null;
  const pct = Number.isFinite(bat.pct) ? bat.pct : Number.isFinite(bat.charge) ? bat.charge : null;
  return { pct: pct === null ? null : Math.min(100, Math.max(0, pct)), charging: bat.charging === true, dock: text(bat.dock ?? bat.dock_state, 40) };
}

function goalOf(goal) {
  if (Array.isArray(goal)) {
    const [x, y, th] = triple(goal, "goal");
    return { name: "", x, y, th, heading: true };
  }
  if (typeof goal !== "object") throw new Error("goal is not an object");
  const [x, y, th] = triple(goal.p, "goal.p");
  return { name: text(goal.name), x, y, th, heading: goal.h !== false };
}

// Where along its path the robot is: the closest point on the path's segments, searched near
// the last answer (the whole path the first time). {index, x, y}: travelled up to vertex
// `index`, then on to (x, y).
export function pathProgress(path, pose, last) {
  const xy = path.xy, n = xy.length / 2;
  if (n === 0) return null;
  const from = last ? Math.max(0, last.index - 5) : 0;
  const to = last ? Math.min(n - 1, last.index + 400) : n - 1;
  let best = { index: 0, x: xy[0], y: xy[1], d: Infinity };
  for (let i = from; i < Math.max(to, from + 1) && i < n; i++) {
    const ax = xy[2 * i], ay = xy[2 * i + 1];
    const bx = i + 1 < n ? xy[2 * i + 2] : ax, by = i + 1 < n ? xy[2 * i + 3] : ay;
    const dx = bx - ax, dy = by - ay, length2 = dx * dx + dy * dy;
    const t = length2 ? Math.max(0, Math.min(1, ((pose.x - ax) * dx + (pose.y - ay) * dy) / length2)) : 0;
    const px = ax + t * dx, py = ay + t * dy;
    const d = Math.hypot(pose.x - px, pose.y - py);
    if (d < best.d) best = { index: i, x: px, y: py, d };
  }
  return best;
}
