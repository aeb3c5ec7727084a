// The map panel: wires the model (map_model.js), the view (view_transform.js), the static
// layers (static_layer.js, drawn in a worker), the per-frame drawing (moving_draw.js) and the
// HUD (hud.js) to the page's WebSocket; acting on the robot from the map: the commands and
// their log (actions.js), the pointer tools (tools.js) and driving by hand (drive.js).
//
// Data flow: a message → MapModel (decoded, checked, or a warning) → a frame is scheduled →
// on the next animation frame: the static bitmap is asked for if the view outgrew the last
// one, and the moving layers are drawn over it. Any number of messages between two frames
// cost one frame; with nothing new, nothing is drawn.
//
// The page opts in with {t: "map", on: true} when the panel is visible (and out when it is
// hidden, so a tree-only page costs the monitor nothing). A monitor without maps answers with
// an error for "map"; the panel swallows it and keeps saying "no map yet".
//
// `window.__map` is for tests and benchmarks: {firstPaint, paints, recordPaints, drawn:
// {points, lines, objects}, moving: {robots, laser, paths, goals, tracked, arrows, trackedLabels,
// detections, names}, labels() (the label boxes the last frame drew, CSS px on the canvas:
// [{kind, text, x0, y0, x1, y1, leader}], labels.js), warnings, objectTip() (the tracked
// object's tooltip text, or null), toScreen(x, y), toWorld(sx, sy), view(), colourOf(ns),
// robot(ns), selected(), fetches, renders, where, frameMs, messageMs}; robot(ns) is a copy of
// what the page knows of a robot (pose, mount, footprint, battery, alive, state, path and scan
// sizes, whether its path is drawn and how far its end is, the running node, the current goal,
// the detector's objects `seen` and the tracker's `tracked`, aged to now), or null; acting()
// what acting from the map stands at ({robot, canAct, mode, points}); highlight() the goal
// ringed for the node selected in the tree ({name, x, y, th, category}, or null).

import { colourOf, onRobotSelected, selectRobot, selectedRobot } from "../robots.js";
import { MapActions } from "./actions.js";
import { Driver } from "./drive.js";
import { coveringBoxes, freeRect } from "./free_area.js";
import { GoalHighlight } from "./goal_highlight.js";
import { Hud } from "./hud.js";
import { labelBoxes } from "./labels.js";
import { describe } from "./map_probe.js";
import { CATEGORY, DETECTIONS_SHOWN_MS, MapModel, parseMapBlob } from "./map_model.js";
import { drawBitmap, drawMoving } from "./moving_draw.js";
import { pickOnClick, robotAt } from "./robot_pick.js";
import { StaticLayer } from "./static_layer.js";
import { ObjectTip } from "./object_tip.js";
import { MapTools } from "./tools.js";
import { TRACKED_SHOWN_MS, trackedAt } from "./tracked_objects.js";
import { ViewTransform } from "./view_transform.js";

const FRAME_SAMPLES = 600;
const MARKERS = new Set([CATEGORY.GOAL, CATEGORY.GOAL_WITH_HEADING, CATEGORY.DOCK, CATEGORY.HOME]);

export class MapPanel {
  // `root`: the #map-view element; `post(message)`: send to the monitor (when connected);
  // `send(command)`: send and get a promise of its result.
  constructor(root, { post, send }) {
    this.root = root;
    this.post = post;
    this.canvas = root.querySelector("#map-canvas"); // what moves; takes the pointer
    this.ctx = this.canvas.getContext("2d");
    this.lower = root.querySelector("#map-static"); // the static bitmap, under it
    this.lowerCtx = this.lower.getContext("2d");
    this.lowerKey = ""; // what the lower canvas shows (bitmap and placement)
    this.model = new MapModel();
    this.view = new ViewTransform();
    this.visible = false;
    this.follow = false;
    this.userMoved = false; // the user zoomed or panned this map: do not re-fit on resize
    this.treeNs = null;
    this.pairs = new Map(); // tree ns -> robot ns, from the monitor's robots list
    this.shownKey = null;
    this.loading = new Map(); // key -> promise
    this.goalHighlight = new GoalHighlight(); // the goal the node selected in the tree names
    this.labels = []; // the labels the last frame placed (labels.js)
    this.covered = []; // the boxes the map's controls cover (free_area.js), as of the last change
    this.scheduled = false;
    this.size = { width: 0, height: 0 };
    this.onEmpty = () => {}; // hears whether there is no map to show (the layout shrinks it)
    const mainThread = new URLSearchParams(location.search).get("map_worker") === "0";
    this.staticLayer = new StaticLayer({ onBitmap: () => this.schedule(), mainThread });
    this.hud = new Hud(root, {
      onLayers: () => this.schedule(),
      onFit: () => this.fit(),
      onFollow: (on) => { this.follow = on; this.schedule(); },
    });
    // acting on the robot: always the robot of the shown tree (selected())
    this.actions = new MapActions(root, { send, robot: () => this.actingRobot(), onChange: () => this.schedule() });
    this.tools = new MapTools(this.canvas, { view: this.view, actions: this.actions, markerAt: (sx, sy, px) => this.markerAt(sx, sy, px), robotAt: (sx, sy) => robotAt(this.model.robots.values(), this.view, sx, sy), schedule: () => this.schedule() });
    this.driver = new Driver(root, { actions: this.actions, post });
    this.objectTip = new ObjectTip(root, this.canvas, (sx, sy, px) => (this.hud.layers.tracked ? trackedAt(this.drawnRobots(), this.view, sx, sy, px) : null));
    const panel = this; // for the getters below
    this.stats = window.__map = {
      firstPaint: null, paints: 0, recordPaints: false, paintTimes: [],
      drawn: { points: 0, lines: 0, objects: 0 }, moving: { robots: 0, laser: 0, paths: 0 },
      fetches: 0, frameMs: [], messageMs: 0, messages: 0,
      get warnings() { return panel.model.warnings.map((w) => ({ ...w })); },
      get renders() { return panel.staticLayer.renders; },
      get where() { return panel.staticLayer.where; },
      toScreen: (x, y) => this.view.toScreen(x, y),
      toWorld: (sx, sy) => this.view.toWorld(sx, sy),
      view: () => this.view.snapshot(),
      colourOf: (ns) => (this.model.robots.has(ns) ? colourOf(ns) : null),
      robot: (ns) => describe(this.model, this.model.robots.get(ns)),
      acting: () => ({ robot: this.actingRobot(), canAct: this.actions.canAct, mode: this.tools.mode, points: this.tools.points.map((p) => [...p]) }),
      highlight: () => this.goalHighlight.target && { ...this.goalHighlight.target },
      selected: () => this.selected(),
      objectTip: () => this.objectTip.text(),
      labels: () => labelBoxes(this.labels),
    };
    // a click on a robot selects it (js/robots.js): its tree is shown, the actions go to it;
    // not while a tool is chosen
    pickOnClick(this.canvas, {
      robotAt: (sx, sy) => (this.tools.ownsClick() ? null : robotAt(this.model.robots.values(), this.view, sx, sy)),
      onPick: (ns) => selectRobot(ns, "map"),
    });
    onRobotSelected(() => this.schedule());
    this.view.attach(this.canvas, {
      claim: (event) => this.tools.claim(event),
      onChange: () => this.schedule(),
      onUser: (gesture) => {
        this.userMoved = true;
        if (gesture !== "zoom" && this.follow) {
          this.follow = false;
          this.hud.setFollow(false);
        }
      },
      onCursor: (sx, sy) => this.hud.showCursor(sx === null || !this.shownKey ? null : this.view.toWorld(sx, sy)),
    });
    new ResizeObserver(([entry]) => {
      this.size = { width: entry.contentRect.width, height: entry.contentRect.height };
      this.schedule();
    }).observe(root);
    this.watchControls();
    this.hud.showStatus("no map yet");
  }

  // ------------------------------------------------------------------ from the page
  // Handles a message from the monitor; true when it was the map's (app.js then ignores it).
  receive(message) {
    const started = performance.now();
    if (message && message.t === "error" && message.command === "map") return true; // a monitor without maps
    if (message && message.t === "robots") this.pairRobots(message);
    if (message && message.t === "seat") {
      this.actions.setSeat(message);
      this.tools.showTour();
      return false; // the page's toolbar shows it too
    }
    if (message && this.actions.receive(message)) {
      this.schedule();
      return true;
    }
    const type = this.model.receive(message);
    if (type === null) return false;
    if (type === "map_ref") this.loadMaps();
    if (type === "det") setTimeout(() => this.schedule(), DETECTIONS_SHOWN_MS + 50); // to wipe them
    if (type === "obj") {
      setTimeout(() => this.schedule(), TRACKED_SHOWN_MS + 50);
      this.hud.autoLayer("detections", false); // the tracker's objects say it better
    }
    this.stats.messages += 1;
    this.stats.messageMs += performance.now() - started;
    this.schedule();
    return true;
  }

  // A message that was not JSON (or not text) at all: a warning, nothing else.
  unreadable(text, error) {
    this.model.warn("", "unreadable", `a message from the monitor could not be read (${error.message}): ${String(text).slice(0, 60)}`);
    this.schedule();
  }

  // The socket (re)opened: sequence numbers start again, and the monitor must hear the opt-in.
  connected() {
    for (const robot of this.model.robots.values()) robot.seq = null;
    if (this.visible) this.post({ t: "map", on: true });
  }

  setVisible(visible) {
    if (visible === this.visible) return;
    this.visible = visible;
    this.post({ t: "map", on: visible });
    if (visible) this.schedule();
  }

  // The tree shown in the tree view: its robot becomes the selected one (/x/bt → /x, unless
  // the monitor's robots list pairs them otherwise).
  setTree(ns) {
    if (ns !== this.treeNs) this.goalHighlight.set([]); // the selection was in another tree
    this.treeNs = ns;
    this.schedule();
  }

  // A node was selected in the tree: `names` are the goal names its properties give
  // (js/node_goals.js), most likely first; the first that is on the map is ringed and brought
  // into view. [] (a node that names none, or none selected) clears it.
  highlightGoal(names) {
    this.goalHighlight.set(names);
    this.schedule();
  }

  // The monitor's robots message: map_robots [{ns, tree, alive, map}] pairs each robot with the
  // tree runner that drives it and says whether it is on the bus (an older monitor's `robot`
  // field in the tree entries is read too).
  pairRobots(message) {
    const robots = Array.isArray(message.map_robots) ? message.map_robots : [];
    const pairs = new Map();
    for (const entry of Array.isArray(message.robots) ? message.robots : []) {
      if (entry && typeof entry.ns === "string" && typeof entry.robot === "string") pairs.set(entry.ns, entry.robot);
    }
    for (const entry of robots) {
      if (!entry || typeof entry.ns !== "string") continue;
      if (typeof entry.tree === "string") pairs.set(entry.tree, entry.ns);
      if (typeof entry.alive === "boolean") this.model.setAlive(entry.ns, entry.alive);
    }
    this.pairs = pairs;
    this.schedule();
  }

  // The robot the map rings and follows: the page's selected robot (js/robots.js) when the map
  // has it, else the one the shown tree drives, else the first.
  selected() {
    const robots = this.model.robots;
    const chosen = selectedRobot();
    if (chosen && robots.has(chosen)) return chosen;
    const ns = this.treeNs ? this.pairs.get(this.treeNs) ?? this.treeNs.replace(/\/bt$/, "") : null;
    if (ns && robots.has(ns)) return ns;
    return [...robots.keys()].sort()[0] ?? null;
  }

  // The robot the map's actions go to: the one of the shown tree (the robot selector's choice),
  // while it is on the bus.
  actingRobot() {
    const ns = this.selected();
    const robot = ns ? this.model.robots.get(ns) : null;
    return robot && robot.alive ? ns : null;
  }

  // The named goal, dock or home of the shown map nearest the screen point (sx, sy), within
  // `px` pixels, as {name, home}; or null.
  markerAt(sx, sy, px) {
    const map = this.model.maps.get(this.shownKey);
    if (!map || !this.hud.layers.goals) return null;
    let best = null, nearest = px;
    for (const item of map.objects) {
      if (!MARKERS.has(item.category) || (!item.name && item.category !== CATEGORY.HOME)) continue;
      const [x, y] = this.view.toScreen(item.x, item.y);
      const distance = Math.hypot(x - sx, y - sy);
      if (distance <= nearest) {
        nearest = distance;
        best = { name: item.name || "home", home: item.category === CATEGORY.HOME };
      }
    }
    return best;
  }

  fit() {
    const map = this.model.maps.get(this.shownKey);
    if (!map) return;
    this.fitMap(map);
    this.schedule();
  }

  // Shows the whole map in the part of the panel its controls leave free (free_area.js).
  fitMap(map) {
    const { width, height } = this.view;
    this.covered = coveringBoxes(this.root, this.canvas);
    this.view.fit(map.bounds, freeRect(width, height, this.covered, (w, h) => ViewTransform.fitScale(map.bounds, w, h)));
    this.userMoved = false;
  }

  // When the toolbar, the actions' bar or STOP changes size (the bar comes with the seat, wraps
  // on a narrower panel): labels keep off it where it is now, and the map is fitted again unless
  // the user moved it. What comes and goes while the user looks (a warning) is kept clear of
  // at the next fit, without moving the map under their eyes.
  watchControls() {
    const observer = new ResizeObserver(() => {
      this.covered = coveringBoxes(this.root, this.canvas);
      if (!this.userMoved) this.fit();
      this.schedule();
    });
    for (const element of this.root.querySelectorAll(".map-tools, #map-act, #map-stop")) observer.observe(element);
  }

  // ------------------------------------------------------------------ maps
  loadMaps() {
    for (const ref of this.model.refs.values()) {
      if (this.model.maps.has(ref.key) || this.loading.has(ref.key)) continue;
      this.hud.showStatus(`loading ${ref.source || "the map"} …`);
      this.stats.fetches += 1;
      const loaded = fetch(ref.url)
        .then((response) => {
          if (!response.ok) throw new Error(`HTTP ${response.status}`);
          return response.arrayBuffer();
        })
        .then((buffer) => {
          const map = parseMapBlob(buffer);
          for (const warning of map.warnings) this.model.warn("", `map ${ref.key}`, warning);
          const counts = ref.counts;
          if (Number.isInteger(counts.points) && counts.points !== map.points.length / 2) {
            this.model.warn("", `map ${ref.key} counts`, `map ${ref.source}: ${map.points.length / 2} points, the monitor announced ${counts.points}`);
          }
          this.model.maps.set(ref.key, map);
        })
        .catch((error) => {
          this.model.warn("", `map ${ref.key}`, `map ${ref.source || ref.key} could not be loaded: ${error.message}`);
        })
        .finally(() => {
          this.loading.delete(ref.key);
          this.model.version += 1;
          this.schedule();
        });
      this.loading.set(ref.key, loaded);
    }
  }

  // The map to show: the selected robot's, else any loaded one. True when the panel went from
  // no map to a map or back (its size may change with that).
  pickMap() {
    const selected = this.selected();
    const ref = selected ? this.model.refs.get(selected) : null;
    let key = ref && this.model.maps.has(ref.key) ? ref.key : null;
    if (!key) key = [...this.model.refs.values()].map((r) => r.key).find((k) => this.model.maps.has(k)) ?? null;
    if (key === this.shownKey) return false;
    const emptiness = !key !== !this.shownKey;
    this.shownKey = key;
    const map = key ? this.model.maps.get(key) : null;
    this.staticLayer.setMap(map);
    this.actions.setGoals(map ? map.objects : []);
    if (map && this.view.width) this.fitMap(map);
    if (emptiness) {
      this.root.classList.toggle("empty", !key);
      this.onEmpty(!key);
    }
    return emptiness;
  }

  // ------------------------------------------------------------------ frames
  schedule() {
    if (this.scheduled || !this.visible) return;
    this.scheduled = true;
    requestAnimationFrame(() => this.frame());
  }

  frame() {
    this.scheduled = false;
    const started = performance.now();
    const { width, height } = this.size;
    if (!width || !height) return;
    const dpr = window.devicePixelRatio || 1;
    if (this.view.resize(width, height) || this.canvas.width !== Math.round(width * dpr)) {
      for (const canvas of [this.canvas, this.lower]) {
        canvas.width = Math.round(width * dpr);
        canvas.height = Math.round(height * dpr);
      }
      this.lowerKey = "";
      const map = this.model.maps.get(this.shownKey);
      if (map && !this.userMoved) this.fitMap(map);
      else this.covered = coveringBoxes(this.root, this.canvas);
    }
    if (this.pickMap()) {
      // the layout may give the panel another size: draw on the next frame, at that size
      this.schedule();
      return;
    }
    const selected = this.selected();
    const followed = this.follow ? this.model.robots.get(selected) : null;
    if (followed && followed.pose) this.view.centerOn(followed.pose.x, followed.pose.y);
    this.goalHighlight.resolve(this.model.maps.get(this.shownKey) ?? null);
    if (this.goalHighlight.reveal(this.view, this.covered)) {
      this.userMoved = true;
      this.follow = false; // the goal asked for is shown, not the robot
      this.hud.setFollow(false);
    }
    const layers = this.hud.layers;
    const ready = this.staticLayer.update(this.view.snapshot(), dpr, layers);
    const robots = this.drawnRobots();
    const placement = this.staticLayer.placement(this.view);
    const lowerKey = placement ? `${placement.serial}:${placement.x}:${placement.y}:${placement.w}:${placement.h}` : "none";
    if (lowerKey !== this.lowerKey) {
      this.lowerKey = lowerKey;
      drawBitmap(this.lowerCtx, this.view, placement, dpr);
    }
    const map = this.model.maps.get(this.shownKey) ?? null;
    const moving = drawMoving(this.ctx, { view: this.view, dpr, model: this.model, map, robots, layers, selected, covered: this.covered });
    this.stats.moving = moving.drawn;
    this.labels = moving.labels;
    this.tools.draw(this.ctx);
    this.objectTip.refresh();
    this.actions.refresh();
    if (this.goalHighlight.draw(this.ctx, this.view)) this.schedule(); // pulsing
    if (this.staticLayer.current) this.stats.drawn = this.staticLayer.current.drawn;
    this.hud.showScale(this.view.scale);
    this.hud.showWarnings(this.model.warnings);
    this.hud.showStatus(this.statusText());
    this.stats.paints += 1;
    const frameMs = this.stats.frameMs;
    frameMs.push(performance.now() - started);
    if (frameMs.length > FRAME_SAMPLES) frameMs.splice(0, frameMs.length - FRAME_SAMPLES);
    this.stamp(placement !== null && ready);
  }

  // The robots on the map shown (or on no map the page has).
  drawnRobots() {
    return [...this.model.robots.values()].filter((robot) => {
      const ref = this.model.refs.get(robot.ns);
      return !ref || !this.shownKey || ref.key === this.shownKey;
    });
  }

  statusText() {
    if (this.shownKey) return "";
    if (this.loading.size) return this.hud.shown.status;
    return "no map yet";
  }

  // A task queued from the next animation frame runs once this frame is on screen: stamp the
  // paint there (as app.js does for the tree).
  stamp(withMap) {
    const firstPaint = withMap && this.stats.firstPaint === null;
    if (!firstPaint && !this.stats.recordPaints) return;
    const seqs = this.stats.recordPaints ? [...this.model.robots.values()].map((r) => [r.ns, r.seq]) : null;
    requestAnimationFrame(() => setTimeout(() => {
      const now = performance.timeOrigin + performance.now();
      if (firstPaint && this.stats.firstPaint === null) this.stats.firstPaint = now;
      if (seqs) this.stats.paintTimes.push([now, seqs]);
    }, 0));
  }
}
