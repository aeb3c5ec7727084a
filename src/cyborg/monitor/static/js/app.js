// The monitor page: connects to the monitor, keeps the model, draws, and wires the controls.
//
// Drawing is coalesced per animation frame: any number of deltas between two frames cost one
// repaint of the nodes they touched. `window.__monitor` exposes counters for tests and the
// latency benchmark (`structures`: structures received; `laidOut`: how many had been received
// when the tree was last laid out).

import { say, selectTreeRobot, showBanner, showToolbar, showTrees } from "./chrome.js";
import { Connection, keepSeatSecret } from "./connection.js";
import { saveView } from "./export.js";
import { History } from "./history.js";
import { Layout, remember, remembered } from "./layout.js";
import { LazyMapPanel } from "./map/lazy_panel.js";
import { TreeModel } from "./model.js";
import { goalNames } from "./node_goals.js";
import { showBlackboard, showNode } from "./panels.js";
import { ModesPanel } from "./modes_panel.js";
import { PlayerBar } from "./player_bar.js";
import { showReplay } from "./replay.js";
import { StopBanner } from "./stop_banner.js";
import { badgeMarkup } from "./services.js";
import { learnRobots, onRobotSelected, treeOfRobot } from "./robots.js";
import { TreeFolds } from "./tree_folds.js";
import { TreeView } from "./tree_view.js";

const $ = (id) => document.getElementById(id);
// The view's choices last until changed (localStorage): "Fit" (the whole tree, at any size)
// and "Fold to fit".
const FIT_ITEM = "cyborg-monitor-fit";
const FOLD_ITEM = "cyborg-monitor-fold";
const stats = (window.__monitor = { messages: 0, structures: 0, laidOut: 0, frames: 0, draws: 0, drawn: 0, tick: 0, paints: [], recordPaints: false, firstPaint: null, drawMs: null });

const model = new TreeModel();
const page = {
  ns: null,
  robots: [],
  alive: false,
  enabled: null,
  hooks: new Map(),
  pausedAt: "",
  manualPause: null, // the tree the monitor paused for a manual goal from the map
  problem: "",
  title: "",
  seat: { may_control: false, control: false, holder: null },
  depth: -1,
  foldLevel: Infinity, // nodes this far from the root or further are folded to fit (see foldLevelToFit)
  folded: new Set(), // folded by hand
  opened: new Set(), // unfolded by hand (wins over draw depth)
  selected: null,
  matches: [],
  matchAt: -1,
  blackboard: null,
  connected: false,
};
const toolbar = () => showToolbar(page, model);
const banner = () => showBanner(page, model);
let needsLayout = true;
let dirty = null; // Set of ids to repaint, or "all"
let layoutKey = "";
let scheduled = false;
let placedFor = null; // the tree version last placed at the readable scale (TreeView.place)
let followed = null; // the end of the running path last scrolled into view

const view = new TreeView($("tree"), {
  onSelect: (id) => select(id),
  onToggle: (id) => toggle(id),
  onUserZoom: () => setAutofit(false),
  badge: (node, width) => badgeMarkup(node, width, model.servicesOn.has(node.id)),
});

const connection = new Connection({
  onMessage: receive,
  onState: (state) => {
    page.connected = state === "open";
    if (page.connected) mapPanel.connected();
    banner();
  },
  onOpen: () => connection.post({ t: "watch", ns: page.ns || "" }),
  onUnreadable: (data, error) => mapPanel.unreadable(data, error),
});
// The map beside the tree (js/map/), loaded once the tree is drawn (js/map/lazy_panel.js); the
// layout says whether it can be seen.
const mapPanel = new LazyMapPanel($("map-view"), { post: (message) => connection.post(message), send: (message) => connection.send(message) });
const layout = new Layout({ onMapShown: (shown) => mapPanel.setVisible(shown) });
mapPanel.onEmpty = (empty) => layout.setMapEmpty(empty);
new ResizeObserver(() => {
  if ($("autofit").checked) view.fit();
  if (!model.root) return;
  // a panel maximised, a tab shown, the splitter dragged: fold again to the new width, and
  // place the tree again unless the user has moved it
  if (!$("autofit").checked && !view.movedByUser()) placedFor = null;
  if (foldLevelToFit() !== page.foldLevel || placedFor !== model.version) relayout();
}).observe($("tree"));
// The ticks the monitor kept, one at a time (js/history.js); `tickHistory.state` is null while live.
const tickHistory = new History({ onShow: () => markDirty("all"), say });
// A played recording's timeline (js/player_bar.js); a jump of the played time leaves the history.
const playerBar = new PlayerBar({ send: (body) => command(body), onJump: () => { if (tickHistory.state) tickHistory.live(); } });
// The mode machine of the shown tree runner, beside the tree (js/modes_panel.js).
const modesPanel = new ModesPanel({ send: (body) => command(body) });
// Trees a STOP halted: a red banner with Resume on every page (js/stop_banner.js).
const stopBanner = new StopBanner({ send: (body) => command(body) });
// Folded and unfolded nodes of each tree shown (a mode's tree keeps them while another runs).
const folds = new TreeFolds();

// ------------------------------------------------------------------ messages
function receive(message) {
  stats.messages += 1;
  stopBanner.receive(message); // reads robots and seat, takes nothing from the rest
  if (mapPanel.receive(message)) return;
  switch (message.t) {
    case "watching":
      page.ns = message.ns;
      treeShown();
      break;
    case "structure":
      stats.structures += 1;
      folds.switchTree(page, message.ns, message.tree ? message.tree.title : "");
      if (message.ns !== page.ns) {
        page.ns = message.ns;
        treeShown();
      }
      model.reset(message.v, message.tree ? message.tree.root : null);
      page.title = message.tree ? message.tree.title : "";
      modesPanel.showTreeMode(page.title, Boolean(model.root));
      if (page.selected && !model.byId.has(page.selected)) page.selected = null;
      needsLayout = true;
      schedule();
      break;
    case "snapshot":
      // one of the robot left behind (still on its way), or a tree not drawn here
      if (message.ns !== page.ns || message.v !== model.version) break;
      model.applySnapshot(message);
      needsLayout = true;
      schedule();
      break;
    case "tick": {
      if (message.ns !== page.ns) break;
      const changed = model.applyFrame(message);
      if (changed === null) break;
      stats.frames += 1;
      stats.tick = model.tick;
      if (changed.activeChanged && visibleKey() !== layoutKey) needsLayout = true;
      if (needsLayout || tickHistory.state) {
        markDirty(changed);
      } else {
        // Class changes are cheap and the browser draws them in its next frame anyway:
        // apply them now rather than waiting for an animation frame.
        addDirty(changed);
        render();
      }
      break;
    }
    case "runner":
      if (message.ns !== page.ns) break;
      page.alive = message.alive;
      page.enabled = message.enabled;
      page.problem = message.problem;
      page.hooks = new Map(message.hooks.map((hook) => [hook.id, hook]));
      modesPanel.setAlive(message.alive);
      page.pausedAt = message.paused_at;
      if (message.enabled !== false || message.stopped) page.manualPause = null; // (a STOP's banner)
      markDirty("all");
      toolbar();
      banner();
      break;
    case "robots":
      learnRobots(message);
      page.robots = message.robots;
      showTrees(page);
      break;
    case "seat":
      page.seat = message;
      if (message.secret) keepSeatSecret(message.secret);
      if (message.may_control && message.holder === null) connection.post({ t: "claim" });
      playerBar.setSeat(message);
      modesPanel.setSeat(message);
      toolbar();
      break;
    case "timing":
      if (message.ns === page.ns && message.v === model.version) {
        model.applyTiming(message.nodes);
        if (page.selected) showNode(model, page.selected, page.hooks);
      }
      break;
    case "blackboard":
      if (message.ns === page.ns) {
        page.blackboard = message.data;
        showBlackboard(message.data, $("bb-filter").value, nodeName);
      }
      break;
    case "services": { // the services on composites: badges and the details panel
      const changed = message.ns === page.ns ? model.applyServices(message) : null;
      if (changed) view.markServices(model.servicesOn, changed);
      if (changed && page.selected) showNode(model, page.selected, page.hooks);
      break;
    }
    case "history":
      tickHistory.start(message, model.version);
      break;
    case "modes":
      if (message.ns !== page.ns) break;
      modesPanel.show(message.ns, message.modes);
      modesPanel.showTreeMode(page.title, Boolean(model.root));
      break;
    case "player": // a played recording: its timeline, and nothing here acts (js/replay.js)
      playerBar.show(message.player);
      showReplay(message.player);
      toolbar();
      break;
    case "manual_pause": // the monitor paused a tree before a goal sent from the map
      page.manualPause = message.tree;
      if (message.tree === page.ns) page.enabled = false;
      toolbar();
      break;
    case "error":
      say(message.message, true);
      break;
    default:
      break;
  }
}

// ------------------------------------------------------------------ drawing
function markDirty(ids) {
  addDirty(ids);
  schedule();
}

function addDirty(ids) {
  if (ids === "all" || dirty === "all") dirty = "all";
  else if (dirty === null) dirty = new Set(ids);
  else for (const id of ids) dirty.add(id);
}

function schedule() {
  if (scheduled) return;
  scheduled = true;
  requestAnimationFrame(() => render(true));
}

function render(fromFrame = false) {
  if (fromFrame) scheduled = false;
  if (tickHistory.state && !needsLayout && dirty !== "all" && !fromFrame) return;
  const started = performance.now();
  const relaid = needsLayout;
  if (needsLayout) {
    needsLayout = false;
    dirty = null;
    page.foldLevel = foldLevelToFit();
    layoutKey = visibleKey();
    stats.drawn = model.root ? view.draw(model.root, isOpen, tickHistory.state ? historyLook() : liveLook()) : view.clear();
    // folded nodes with part of the running path inside are known only once drawn
    dirty = new Set(model.active.flatMap((id) => model.ancestors(id)));
    stats.draws += 1;
    stats.laidOut = stats.structures;
    if ($("autofit").checked) view.fit();
    else if (placedFor !== model.version) {
      followed = runningEnd();
      if (view.place(followed)) placedFor = model.version;
    }
    applySearch(false);
    if (page.selected) view.markClass("selected", new Set([page.selected]));
  }
  if (dirty !== null) {
    const shown = tickHistory.state ? historyLook() : liveLook();
    view.paint(dirty === "all" ? null : dirty, shown);
    dirty = null;
    if (page.selected) showNode(model, page.selected, page.hooks);
  }
  followRunningPath(relaid);
  if (relaid) stats.drawMs = performance.now() - started;
  tickInfo();
  // A task queued from an animation frame runs once that frame has been rendered: stamp the
  // paint there — from this frame when the render runs in one, else from the next.
  const tick = model.tick;
  const firstDraw = stats.firstPaint === null && stats.drawn > 0;
  if (firstDraw || stats.recordPaints) {
    const stamp = () => {
      const now = performance.timeOrigin + performance.now();
      if (firstDraw && stats.firstPaint === null) {
        stats.firstPaint = now;
        mapPanel.load(); // the tree is on screen: now the map's code may come
      }
      if (stats.recordPaints) stats.paints.push([tick, now]);
    };
    if (fromFrame) setTimeout(stamp, 0);
    else requestAnimationFrame(() => setTimeout(stamp, 0));
  }
}

function liveLook() {
  return { code: (id) => model.code(id), active: model.activeSet, inside: insideActive(model.active), hooked: new Set(page.hooks.keys()), pausedAt: page.pausedAt };
}

function historyLook() {
  const state = tickHistory.at(model.ids.length);
  const active = new Set(state.active.map((index) => model.ids[index]));
  return { code: (id) => state.codes[model.indexOf.get(id)] ?? 0, active, inside: insideActive([...active]), hooked: new Set(), pausedAt: "" };
}

// The drawn node where the running path ends (the deepest one drawn), or null.
function runningEnd() {
  for (let i = model.active.length - 1; i >= 0; i--) {
    if (view.elements.has(model.active[i])) return model.active[i];
  }
  return null;
}

// When the running path has moved, scroll its end into view if it went off-screen (the view
// leaves it be while the user pans; "Fit" shows everything anyway), and name it in the path bar.
function followRunningPath(relaid) {
  const end = runningEnd();
  if (end === followed && !relaid) return;
  const moved = end !== followed;
  followed = end;
  view.setPath(tickHistory.state ? [] : model.active.filter((id) => view.elements.has(id)));
  if (moved && end && !tickHistory.state && !$("autofit").checked) view.reveal(end);
}

// Folded nodes drawn with part of the running path hidden inside them.
function insideActive(active) {
  const inside = new Set();
  for (const id of active) {
    if (view.elements.has(id)) continue;
    for (const up of model.ancestors(id)) {
      if (view.elements.has(up)) { inside.add(up); break; }
    }
  }
  return inside;
}

// rqt_bt's Draw depth, hand folding, folding to fit, and the running path always shown.
function isOpen(node) {
  return isOpenFolding(node, page.foldLevel);
}

function isOpenFolding(node, foldLevel) {
  if (!node.children.length) return false;
  if (page.folded.has(node.id)) return false;
  if (page.opened.has(node.id)) return true;
  if (model.activeSet.has(node.id)) return true;
  if (page.depth >= 0 && node.children.some((child) => child.depth > page.depth)) return false;
  if (model.level.get(node.id) >= foldLevel) return false;
  return true;
}

// As Groot2 folds subtrees: the deepest level of nodes that can stay unfolded with the tree
// still as wide as the view at the readable scale; the nodes from that level down are folded
// (not the running path, nor what the user unfolded). At least the root's children are shown;
// Infinity when everything fits or "Fold to fit" is off. Each try lays out only what it shows,
// from the smallest up, so a large tree costs little more than the layout it ends with.
function foldLevelToFit() {
  if (!$("foldfit").checked || !model.root) return Infinity;
  let deepest = 0;
  for (const level of model.level.values()) deepest = Math.max(deepest, level);
  for (let level = 1; level < deepest; level++) {
    if (!view.fitsReadable(model.root, (node) => isOpenFolding(node, level + 1))) return level;
  }
  return Infinity;
}

function visibleKey() {
  if (!model.root) return "";
  const open = [];
  const stack = [model.root];
  while (stack.length) {
    const node = stack.pop();
    if (isOpen(node)) { open.push(node.id); stack.push(...node.children); }
  }
  return open.join("\u0000");
}

function relayout() {
  needsLayout = true;
  schedule();
}

function toggle(id) {
  const node = model.byId.get(id);
  if (!node || !node.children.length) return;
  if (isOpen(node)) { page.folded.add(id); page.opened.delete(id); }
  else { page.opened.add(id); page.folded.delete(id); }
  relayout();
}

function select(id) {
  page.selected = id;
  view.markClass("selected", new Set(id ? [id] : []));
  showNode(model, id, page.hooks);
  mapPanel.highlightGoal(goalNames(model.byId.get(id))); // its goal ringed on the map
}

function tickInfo() {
  const names = ["", "success", "failure", "running", "error"];
  const source = tickHistory.state ? tickHistory.at(0) : model;
  const root = tickHistory.state ? source.root : model.rootStatus;
  $("tickinfo").textContent = model.root
    ? `${page.title || ""} · tick ${source.tick} · t = ${Number(source.time).toFixed(2)} s · ${Number(source.duration).toFixed(3)} ms · ${names[root] || "–"} · ${stats.drawn} of ${model.ids.length} nodes drawn`
    : "";
}

// ------------------------------------------------------------------ commands
async function command(body) {
  const result = await connection.send(body);
  say(result.message, !result.ok);
  return result;
}

function nodeName(id) {
  const node = model.byId.get(id);
  return node ? `${node.label || node.name} (${id.slice(-8)})` : id;
}

// ------------------------------------------------------------------ search
function applySearch(jump) {
  const needle = $("search").value.trim().toLowerCase();
  page.matches = [];
  if (needle) {
    for (const id of model.ids) {
      const node = model.byId.get(id);
      if (`${node.label} ${node.name} ${id}`.toLowerCase().includes(needle)) page.matches.push(id);
    }
  }
  view.markClass("match", new Set(page.matches));
  $("search-count").textContent = needle ? `${page.matches.length} found` : "";
  if (jump && page.matches.length) {
    page.matchAt = (page.matchAt + 1) % page.matches.length;
    const id = page.matches[page.matchAt];
    let opened = false;
    for (const up of model.ancestors(id)) {
      if (!view.elements.has(id) && (page.folded.delete(up) || !isOpen(model.byId.get(up)))) { page.opened.add(up); opened = true; }
    }
    if (opened) { render(); }
    $("search-count").textContent = `${page.matchAt + 1} of ${page.matches.length}`;
    select(id);
    view.centerOn(id);
    setAutofit(false);
  }
}

// ------------------------------------------------------------------ the selected robot
// Choosing in the robot selector shows that tree; a robot selected elsewhere (a click on the
// map) shows the tree that drives it (js/robots.js).
function showTree(ns) {
  if (ns === page.ns) return;
  page.ns = ns;
  page.folded.clear();
  page.opened.clear();
  page.selected = null;
  tickHistory.live();
  connection.post({ t: "watch", ns: page.ns });
  treeShown();
}

function treeShown() {
  selectTreeRobot(page);
  mapPanel.setTree(page.ns);
}

onRobotSelected((ns, from) => { if (from !== "tree") showTree(treeOfRobot(ns)); });
$("robot").addEventListener("change", (event) => showTree(event.target.value));
$("run").addEventListener("click", () => command({ t: "enable", on: page.enabled === false }));
$("depth").addEventListener("change", (event) => {
  page.depth = Math.max(-1, parseInt(event.target.value, 10) || 0);
  relayout();
});
$("fit").addEventListener("click", () => view.fit(true));
$("readable").addEventListener("click", () => { setAutofit(false); view.place(runningEnd()); });
$("autofit").addEventListener("change", (event) => {
  setAutofit(event.target.checked);
  if (event.target.checked) view.fit();
  else view.place(runningEnd());
});
$("foldfit").addEventListener("change", (event) => {
  remember(FOLD_ITEM, String(event.target.checked));
  relayout();
});
$("highlight").addEventListener("change", (event) => { view.highlight = event.target.checked; });
$("refresh").addEventListener("click", () => { connection.post({ t: "refresh" }); relayout(); });
$("search").addEventListener("input", () => { page.matchAt = -1; applySearch(false); });
$("search").addEventListener("keydown", (event) => { if (event.key === "Enter") applySearch(true); });
$("take").addEventListener("click", () => command({ t: "claim", force: true }));
$("step").addEventListener("click", () => command({ t: "step" }));
$("resume").addEventListener("click", () => command({ t: "resume" }));
$("manual-resume").addEventListener("click", () => command({ t: "enable", on: true, ns: page.manualPause || page.ns }));
$("history").addEventListener("click", () => connection.post({ t: "history" }));
$("bb-filter").addEventListener("input", () => { if (page.blackboard) showBlackboard(page.blackboard, $("bb-filter").value, nodeName); });
for (const button of document.querySelectorAll("#inspector button[data-action]")) {
  button.addEventListener("click", () => {
    if (!page.selected) return;
    command({ t: "control", id: page.selected, action: button.dataset.action, status: button.dataset.status || "failure", once: $("once").checked, keep: $("keep").checked });
  });
}
for (const button of document.querySelectorAll("button[data-export]")) {
  button.addEventListener("click", () => exportView(button.dataset.export));
}
window.addEventListener("resize", () => { if ($("autofit").checked) view.fit(); });

// Save what is shown (js/export.js): SVG and PNG from the page's drawing; DOT from the server,
// told which nodes are folded.
async function exportView(format) {
  if (!model.root) return;
  const collapsed = [...view.elements.keys()].filter((id) => {
    const node = model.byId.get(id);
    return node && node.children.length && !isOpen(node);
  });
  try {
    const result = await saveView({ ns: page.ns, format, collapsed, svg: $("tree"), bounds: view.bounds, title: page.title });
    say(result.message, !result.ok);
  } catch (error) {
    say(`could not save as ${format.toUpperCase()}: ${error.message || error}`, true);
  }
}

function setAutofit(on) {
  $("autofit").checked = on;
  remember(FIT_ITEM, String(on));
}
$("autofit").checked = remembered(FIT_ITEM, "false") === "true";
$("foldfit").checked = remembered(FOLD_ITEM, "true") === "true";

toolbar();
connection.open();
