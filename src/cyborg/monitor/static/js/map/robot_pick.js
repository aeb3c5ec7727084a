// Picking a robot on the map: a click (or tap) on a robot selects it (js/robots.js), which
// shows its tree and makes it the robot the map's actions go to.
//
// `robotAt(robots, view, sx, sy)` is the robot under the screen point (CSS px on the map's
// canvas): the one whose centre is nearest, within its footprint's reach or PICK_PX, however
// far out the map is zoomed. `pickOnClick(canvas, {robotAt, onPick})` calls
// `onPick(ns)` for a click that did not drag the map (the pointer moved at most DRAG_PX between
// press and release) and landed on a robot; other clicks are left to whoever else listens.

const PICK_PX = 12; // a robot drawn small can still be hit this far from its centre
const DRAG_PX = 4;

// The robot (its ns) under (sx, sy), or null. `robots`: the model's robots ({ns, pose, footprint}).
export function robotAt(robots, view, sx, sy) {
  let best = null;
  let bestDistance = Infinity;
  for (const robot of robots) {
    if (!robot.pose) continue;
    const [rx, ry] = view.toScreen(robot.pose.x, robot.pose.y);
    const distance = Math.hypot(rx - sx, ry - sy);
    if (distance <= Math.max(PICK_PX, reach(robot.footprint) * view.scale) && distance < bestDistance) {
      best = robot.ns;
      bestDistance = distance;
    }
  }
  return best;
}

// How far the footprint reaches from the robot's centre, m.
function reach(footprint) {
  let most = 0;
  for (let i = 0; i + 1 < footprint.length; i += 2) most = Math.max(most, Math.hypot(footprint[i], footprint[i + 1]));
  return most;
}

// Listens for clicks on `canvas` that pick a robot (see above).
export function pickOnClick(canvas, { robotAt: find, onPick }) {
  let pressed = null;
  canvas.addEventListener("pointerdown", (event) => { pressed = [event.clientX, event.clientY]; });
  canvas.addEventListener("click", (event) => {
    const moved = pressed ? Math.hypot(event.clientX - pressed[0], event.clientY - pressed[1]) : 0;
    pressed = null;
    if (moved > DRAG_PX) return;
    const box = canvas.getBoundingClientRect();
    const ns = find(event.clientX - box.left, event.clientY - box.top);
    if (ns !== null) onPick(ns);
  });
}
