// What the page shows around the tree about the runner, the seat and the connection: the
// toolbar (Run/Pause, who holds the control seat, Take control, where a breakpoint waits, a tree
// paused for a manual goal from the map), the banner (connection lost, a problem with the tree,
// the runner gone), the robot selector and the message line. Each function redraws its part
// from app.js's `page` state and the tree model; none keeps state of its own.

import { replaying, sayWhyOff } from "./replay.js";
import { colourOf, knownRobots, robotOfTree, selectRobot, treeOfRobot } from "./robots.js";

const $ = (id) => document.getElementById(id);

export function showToolbar(page, model) {
  const seat = page.seat;
  const mayAct = seat.control && page.alive && !replaying();
  for (const button of document.querySelectorAll("button.control")) {
    button.disabled = !mayAct;
    sayWhyOff(button); // a played recording: the tooltip says why it is off
  }
  const run = $("run");
  run.textContent = page.enabled === false ? "▶ Run" : "❚❚ Pause";
  run.dataset.enabled = String(page.enabled);
  run.disabled = !mayAct || page.enabled === null;
  const seatLabel = $("seat");
  seatLabel.className = `seat ${seat.control ? "control" : "view"}`;
  seatLabel.textContent = seat.control ? "You have control" : seat.may_control ? (seat.holder ? "Another page has control" : "View only") : "View only";
  $("take").hidden = !(seat.may_control && !seat.control);
  $("paused").hidden = !page.pausedAt;
  // "Tree paused for a manual goal — Resume": the monitor paused it before a goal from the map
  $("manual-pause").hidden = !(page.manualPause && page.manualPause === page.ns && page.enabled === false);
  const pausedNode = model.byId.get(page.pausedAt);
  $("paused-node").textContent = pausedNode ? pausedNode.label || pausedNode.name : page.pausedAt;
}

export function showBanner(page, model) {
  const el = $("banner");
  let text = "";
  el.className = "";
  if (!page.connected) text = "Connection to the monitor lost — reconnecting…";
  else if (page.problem) text = page.problem;
  else if (!page.alive) {
    text = `The tree runner ${page.ns || ""} is not running — waiting for it to come back.`;
    el.className = "info";
  }
  el.textContent = text;
  el.hidden = !text;
  showToolbar(page, model);
}

// The robot selector: every robot and every tree runner the monitor follows, one entry each
// (a robot with the tree that drives it, a tree runner without a robot, a robot without a
// tree), with the robot's colour swatch (js/robots.js's colourOf, as on the map) and name.
// An entry's value is the tree's namespace (a robot without a tree: where its tree would be),
// so choosing one shows that tree; the swatch beside the list shows the selected robot's colour.
export function showTrees(page) {
  const select = $("robot");
  const current = page.ns;
  const entries = selectorEntries(page.robots);
  select.innerHTML = "";
  for (const entry of entries) {
    const option = document.createElement("option");
    option.value = entry.tree;
    const name = entry.robot || entry.tree; // as the map names it
    const title = entry.title ? ` — ${entry.title}` : "";
    option.textContent = `${entry.robot ? "● " : ""}${name}${title}${entry.alive ? "" : " (offline)"}`;
    if (entry.robot) {
      option.dataset.robot = entry.robot;
      option.dataset.colour = colourOf(entry.robot);
      option.style.color = option.dataset.colour;
    }
    select.append(option);
  }
  if (current) select.value = current;
  showSwatch(page);
}

// The tree shown is page.ns (chosen here or by the monitor): the selector shows it, and the
// robot it drives becomes the selected robot (js/robots.js).
export function selectTreeRobot(page) {
  const select = $("robot");
  if ([...select.options].some((option) => option.value === page.ns)) select.value = page.ns;
  const option = select.selectedOptions[0];
  const robot = option && option.value === page.ns && option.dataset.robot ? option.dataset.robot : robotOfTree(page.ns);
  selectRobot(robot, "tree");
  showSwatch(page);
}

// The selected robot's colour beside the selector (none for a tree without a robot).
function showSwatch(page) {
  const swatch = $("robot-swatch");
  const option = $("robot").selectedOptions[0];
  const robot = option ? option.dataset.robot : null;
  swatch.style.background = robot ? colourOf(robot) : "transparent";
  swatch.title = robot || page.ns || "";
  swatch.hidden = !robot;
}

// [{tree, robot (ns or null), title, alive}]: the tree runners, each with the robot it drives
// when the monitor knows that robot, then the robots no runner drives.
function selectorEntries(trees) {
  const robots = new Map(knownRobots().map((robot) => [robot.ns, robot]));
  const entries = trees.map((tree) => {
    const robot = robotOfTree(tree.ns);
    return { tree: tree.ns, robot: robots.has(robot) ? robot : null, title: tree.title, alive: tree.alive };
  });
  const driven = new Set(entries.map((entry) => entry.robot));
  for (const robot of robots.values()) {
    if (!driven.has(robot.ns)) entries.push({ tree: treeOfRobot(robot.ns), robot: robot.ns, title: "", alive: robot.alive });
  }
  return entries;
}

export function say(text, error = false) {
  const el = $("message");
  el.textContent = text;
  el.className = error ? "error" : "";
}
