// The objects a robot's tracker follows (the monitor's `obj` message, docs/monitor.md): read,
// checked, and aged as time goes on. The drawing is tracked_draw.js; the tooltip object_tip.js.
//
//   {t:"obj", ns, id, stamp, o:[{id, label, x, y, vx, vy, conf, age, seen}]}
//       x, y in m (map frame), vx, vy in m/s, conf 0-1, age the seconds since the object was
//       last seen as of the message's stamp, seen the number of frames it was seen in.
//
// Each message replaces the robot's list: an object that is not in it any more is gone. A
// list is shown for TRACKED_SHOWN_MS after it came (the tracker renews it at least once a
// second; one that stopped leaves nothing behind for long), and each object's age goes on
// counting from when the list came, so it fades between messages too.

export const TRACKED_SHOWN_MS = 3000;
export const FADE_S = 5; // the tracker's FORGET_AFTER: an object this old is as faded as it gets
export const MIN_ALPHA = 0.25;
const MAX_TRACKED = 256;

// The robot's list from an `obj` message: {at (ms), stamp, items}; throws on a malformed one
// (the model turns that into a warning and keeps what it had).
export function readTracked(message, now = Date.now()) {
  const items = message.o;
  if (!Array.isArray(items)) throw new Error("o is not a list of objects");
  if (items.length > MAX_TRACKED) throw new Error(`${items.length} objects, more than the ${MAX_TRACKED} drawn`);
  const ids = new Set();
  const read = [];
  items.forEach((item, i) => {
    if (!item || typeof item !== "object") throw new Error(`o[${i}] is not an object`);
    if (!Number.isInteger(item.id) || item.id < 0) throw new Error(`o[${i}].id is not an id (${String(item.id).slice(0, 20)})`);
    if (!Number.isFinite(item.x) || !Number.isFinite(item.y)) throw new Error(`o[${i}] has no place (x, y)`);
    if (ids.has(item.id)) return; // the first object of an id wins, as on the monitor
    ids.add(item.id);
    read.push({
      id: item.id, label: typeof item.label === "string" ? item.label.slice(0, 60) : "", x: item.x, y: item.y,
      vx: number(item.vx), vy: number(item.vy), conf: Math.min(1, Math.max(0, number(item.conf))),
      age: Math.max(0, number(item.age)), seen: Number.isInteger(item.seen) ? item.seen : null,
    });
  });
  return { at: now, stamp: number(message.stamp), items: read };
}

// The robot's objects as of `now` (none once its list is TRACKED_SHOWN_MS old), each with its
// age counted on to now and the opacity that age gives: 1 when just seen, down to MIN_ALPHA at
// FADE_S and beyond.
export function trackedNow(robot, now = Date.now()) {
  const tracked = robot.tracked;
  if (!tracked || now - tracked.at >= TRACKED_SHOWN_MS) return [];
  const since = Math.max(0, now - tracked.at) / 1000;
  return tracked.items.map((item) => {
    const age = item.age + since;
    return { ...item, age, alpha: 1 - (1 - MIN_ALPHA) * Math.min(1, age / FADE_S) };
  });
}

// The object of the robots drawn whose marker is nearest the screen point (sx, sy), within
// `px` pixels: {robot (ns), item}, or null.
export function trackedAt(robots, view, sx, sy, px, now = Date.now()) {
  let best = null, nearest = px;
  for (const robot of robots) {
    if (!robot.alive) continue;
    for (const item of trackedNow(robot, now)) {
      const [x, y] = view.toScreen(item.x, item.y);
      const distance = Math.hypot(x - sx, y - sy);
      if (distance <= nearest) {
        nearest = distance;
        best = { robot: robot.ns, item };
      }
    }
  }
  return best;
}

function number(value) {
  return Number.isFinite(value) ? value : 0;
}
