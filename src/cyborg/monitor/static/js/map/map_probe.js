// What `window.__map.robot(ns)` gives tests and benchmarks: a copy of what the page knows of a
// robot, so a test can read it without touching the live state (map_panel.js).

import { trackedNow } from "./tracked_objects.js";

// A copy of `robot` (the model's state), or null: its pose, mount, footprint, battery,
// whether it is alive, its path state, path and scan sizes, whether its path is drawn and
// how far its end is, the running node, the current goal, the detector's objects (`seen`) and
// the tracker's (`tracked`, aged to now, each with the opacity it is drawn with).
export function describe(model, robot) {
  if (!robot) return null;
  const xy = robot.path?.xy;
  const end = xy && xy.length ? [xy[xy.length - 2], xy[xy.length - 1]] : null;
  return {
    pathShown: model.pathShown(robot), toGo: end && robot.pose ? Math.hypot(end[0] - robot.pose.x, end[1] - robot.pose.y) : null,
    ns: robot.ns, pose: robot.pose && { ...robot.pose }, mount: robot.mount, footprint: [...robot.footprint],
    battery: robot.battery && { ...robot.battery }, alive: robot.alive, state: robot.state, pathId: robot.pathId,
    path: robot.path ? robot.path.xy.length / 2 : 0, scan: robot.scanCount, colour: robot.colour,
    node: robot.node, goal: robot.goal && { ...robot.goal }, seen: model.seenNow(robot).map((item) => ({ ...item })),
    tracked: trackedNow(robot),
  };
}
