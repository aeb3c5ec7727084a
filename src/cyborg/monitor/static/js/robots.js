// The robots the page knows, the colour of each, and the selected one.
//
// The selected robot is THE robot of the page: the tree view shows its tree, the map rings
// and follows it, and what the map's actions do goes to it. `selectedRobot()` names it (its
// namespace, "/robot1"), or null while the page knows no robot. It is chosen in the robot
// selector (js/chrome.js), by clicking a robot on the map (js/map/robot_pick.js), or follows
// the tree the monitor first shows.
//
// Robots are paired with the tree runners that drive them from the monitor's `robots` message
// (`map_robots`: [{ns, tree, alive, map}]); a robot or tree it does not pair goes by the
// convention of `cyborg up`: the runner under /robot1/bt drives /robot1.
//
// `colourOf(ns)` is the one function that decides a robot's colour, for the selector and the
// map alike. A robot keeps its colour for as long as the page lives: colours are handed out in
// the order robots are first seen (those seen together in sorted order), never taken back, so a
// robot that comes later never repaints one already on screen.

export const PALETTE = ["#1a73e8", "#e8710a", "#188038", "#a142f4", "#d01884", "#12b5cb", "#9e6a03", "#3c4043"];
const RUNNER_UNDER_ROBOT = "/bt";

const colours = new Map(); // robot ns -> colour
const robots = new Map(); // robot ns -> {ns, tree (ns or null), alive}
const listeners = new Set();
let selected = null;

// The colour of the robot `ns` (a CSS colour, "#rrggbb"); the first call for a robot chooses it.
export function colourOf(ns) {
  let colour = colours.get(ns);
  if (colour === undefined) {
    colour = PALETTE[colours.size % PALETTE.length];
    colours.set(ns, colour);
  }
  return colour;
}

// The robot the page has selected (see the top of this file), or null.
export function selectedRobot() {
  if (selected !== null) return selected;
  const first = [...robots.keys()].sort()[0];
  return first ?? null;
}

// Selects the robot `ns`. `from` says who chose ("selector", "map", "tree"); listeners hear
// (ns, from) when the selection changed.
export function selectRobot(ns, from = "") {
  if (typeof ns !== "string" || ns === selected) return;
  selected = ns;
  colourOf(ns);
  for (const listener of listeners) listener(ns, from);
}

// Calls `listener(ns, from)` whenever another robot is selected; returns a function that stops it.
export function onRobotSelected(listener) {
  listeners.add(listener);
  return () => listeners.delete(listener);
}

// Learns the robots and their trees from the monitor's `robots` message: the robots it lists
// now (one it no longer follows is forgotten, its colour kept). A message without `map_robots`
// changes nothing.
export function learnRobots(message) {
  if (!message || !Array.isArray(message.map_robots)) return;
  robots.clear();
  for (const entry of message.map_robots) {
    if (!entry || typeof entry.ns !== "string") continue;
    robots.set(entry.ns, { ns: entry.ns, tree: typeof entry.tree === "string" ? entry.tree : null, alive: entry.alive !== false });
  }
  for (const ns of [...robots.keys()].sort()) colourOf(ns);
}

// The robots the page knows of, sorted by namespace: [{ns, tree, alive}].
export function knownRobots() {
  return [...robots.values()].sort((a, b) => (a.ns < b.ns ? -1 : a.ns > b.ns ? 1 : 0)).map((robot) => ({ ...robot }));
}

// The robot the tree runner under `tree` drives: the monitor's pairing, else /x/bt → /x; null
// for a runner that names no robot.
export function robotOfTree(tree) {
  if (typeof tree !== "string") return null;
  for (const robot of robots.values()) if (robot.tree === tree) return robot.ns;
  const ns = tree.endsWith(RUNNER_UNDER_ROBOT) ? tree.slice(0, -RUNNER_UNDER_ROBOT.length) : "";
  return ns || null;
}

// The tree runner that drives the robot `ns`: the monitor's pairing, else /x → /x/bt.
export function treeOfRobot(ns) {
  const robot = robots.get(ns);
  if (robot && robot.tree) return robot.tree;
  return `${ns === "/" ? "" : ns}${RUNNER_UNDER_ROBOT}`;
}
