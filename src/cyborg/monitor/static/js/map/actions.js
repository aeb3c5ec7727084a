// Acting from the map: the commands this page sends to the robot of the shown tree (go to a
// goal or a pose, set pose, home, dock, undock, stop, a tour), the buttons that send them, and
// the map's action log with each result as it comes.
//
// Rules (the monitor enforces them; the page only shows them): every action but Stop needs the
// control seat, so the buttons are disabled without it and say why; Stop needs only that this
// page may control (loopback or the token) and always shows. While a played recording is
// shown (js/replay.js) every action, Stop too, is off and says why: nothing would carry it out.
// Which robot: `robot()`, given by the panel, the one function that says whose commands these
// are (the robot of the shown tree).
//
// Answers: the command's `result` (accepted or refused, and whether the tree was paused for
// it), then for a goal a `robot_result` when it ends (reached, failed, canceled, no_path), and
// `tour` messages as a tour goes on. Each becomes a row of the log, updated in place.

import { say } from "../chrome.js";
import { onReplay, replaying, REPLAY_WHY } from "../replay.js";
import { CATEGORY } from "./map_model.js";

const LOG_KEPT = 8;
export const ROBOT_COMMANDS = new Set(["go", "go_pose", "home", "dock", "undock", "set_pose", "stop", "drive", "tour"]);
const GOAL_CATEGORIES = new Set([CATEGORY.GOAL, CATEGORY.GOAL_WITH_HEADING, CATEGORY.DOCK]);
const VIEW_ONLY = "view only: open the monitor on the robot's machine, or with its token";
const NO_SEAT = "take control (top right) to act on the robot";
const OUTCOME_TEXT = { reached: "reached", failed: "failed", canceled: "cancelled", no_path: "no path" };

export class MapActions {
  // `root`: #map-view; `send(command)`: a promise of its result; `robot()`: the robot acted on
  // (ns) or null; `onChange()`: the tools' look changed (redraw).
  constructor(root, { send, robot, onChange }) {
    const $ = (selector) => root.querySelector(selector);
    this.root = root;
    this.send = send;
    this.robot = robot;
    this.onChange = onChange;
    this.seat = { may_control: false, control: false, holder: null };
    this.bar = $("#map-act");
    this.robotName = $("#map-act-robot");
    this.stopButton = $("#map-stop");
    this.goalList = $("#map-goal");
    this.logList = $("#map-log");
    this.rows = []; // {key, item, text}
    this.tour = null; // the monitor's latest tour message for the robot acted on
    this.shownKey = "";
    this.onDriveEnded = () => {}; // (zero): driving by hand must end now (js/map/drive.js sets it)
    for (const element of this.bar.querySelectorAll("button, select")) element.dataset.tip = element.title;
    this.stopButton.dataset.tip = this.stopButton.title;
    this.stopButton.addEventListener("click", () => this.stop());
    onReplay(() => this.refresh());
    $("#map-home").addEventListener("click", () => this.act({ t: "home" }, "home"));
    $("#map-dock").addEventListener("click", () => this.act({ t: "dock" }, "dock"));
    $("#map-undock").addEventListener("click", () => this.act({ t: "undock" }, "undock"));
    this.goalList.addEventListener("change", () => {
      const name = this.goalList.value;
      this.goalList.value = "";
      if (name) this.go(name);
    });
    this.refresh();
  }

  // ------------------------------------------------------------------ state
  setSeat(seat) {
    this.seat = { may_control: !!seat.may_control, control: !!seat.control, holder: seat.holder ?? null };
    this.refresh();
  }

  // Whether this page may act now (holds the seat, and there is a robot to act on).
  get canAct() {
    return this.seat.control && this.robot() !== null && !replaying();
  }

  // Why the page may not act, or "".
  whyNot() {
    if (replaying()) return REPLAY_WHY;
    if (!this.seat.may_control) return VIEW_ONLY;
    if (!this.seat.control) return NO_SEAT;
    if (this.robot() === null) return "no robot on the map";
    return "";
  }

  // Enables the buttons for the page that may act, and says why not on the others; cheap when
  // nothing changed (called every frame).
  refresh() {
    const ns = this.robot();
    const why = this.whyNot();
    const key = `${ns}|${why}`;
    if (key === this.shownKey) return;
    this.shownKey = key;
    this.root.classList.toggle("acting", !why);
    this.bar.hidden = !this.seat.may_control;
    this.bar.title = why ? `Acting on the robot: ${why}` : "";
    this.robotName.textContent = ns ? `→ ${ns}` : "";
    for (const element of this.bar.querySelectorAll("button, select")) {
      element.disabled = !!why;
      element.title = why ? `${element.dataset.tip} (${why})` : element.dataset.tip;
    }
    const stopWhy = replaying() ? REPLAY_WHY : !this.seat.may_control ? VIEW_ONLY : ns === null ? "no robot on the map" : "";
    this.stopButton.disabled = !!stopWhy;
    this.stopButton.title = stopWhy ? `${this.stopButton.dataset.tip} (${stopWhy})` : this.stopButton.dataset.tip;
    this.onChange();
  }

  // The goal list from the shown map's objects (goals and docks with a name).
  setGoals(objects) {
    const names = [...new Set(objects.filter((item) => GOAL_CATEGORIES.has(item.category) && item.name).map((item) => item.name))].sort();
    const options = names.map((name) => {
      const option = document.createElement("option");
      option.value = name;
      option.textContent = name;
      return option;
    });
    this.goalList.replaceChildren(this.goalList.options[0], ...options);
  }

  // ------------------------------------------------------------------ commands
  go(name) {
    return this.act({ t: "go", goal: name }, `go to ${name}`);
  }

  goPose(x, y, th) {
    return this.act({ t: "go_pose", pose: pose(x, y, th) }, `go to ${poseText(x, y, th)}`);
  }

  setPose(x, y, th) {
    return this.act({ t: "set_pose", pose: pose(x, y, th) }, `set pose ${poseText(x, y, th)}`);
  }

  startTour(points) {
    return this.act({ t: "tour", points: points.map(([x, y, th]) => pose(x, y, th)) }, `tour of ${points.length} points`);
  }

  stop() {
    this.onDriveEnded(false); // a key or the joystick held here drives no more (the stop follows)
    return this.act({ t: "stop" }, "STOP", true);
  }

  // Sends `command` to the robot acted on; a log row shows it and then its answer.
  async act(command, text, evenWithoutSeat = false) {
    const ns = this.robot();
    if (replaying()) {
      say(`${text}: ${REPLAY_WHY}`, true);
      return null;
    }
    if (ns === null || !(evenWithoutSeat ? this.seat.may_control : this.canAct)) return null;
    const row = this.log(`${ns}: ${text}`, "pending");
    const result = await this.send({ ...command, ns });
    const goal = typeof result.goal === "string" ? result.goal : null;
    if (goal !== null) row.key = `${ns}|${goal}`;
    const paused = result.paused ? ` — tree ${result.paused} paused` : "";
    const stopped = result.stopped?.length ? ` — tree ${result.stopped.join(", ")} stopped until resumed` : "";
    this.update(row, result.ok ? (goal !== null ? "pending" : "ok") : "error", `${ns}: ${text} — ${result.ok ? (goal !== null ? "on its way" : "done") : "refused"}${paused}${stopped}`, result.message);
    say(result.message, !result.ok);
    return result;
  }

  // ------------------------------------------------------------------ from the monitor
  // A message for the actions: true when it was one (robot_result, tour, a refused drive).
  receive(message) {
    if (message.t === "robot_result") {
      const key = `${message.ns}|${message.goal}`;
      const row = this.rows.find((each) => each.key === key && each.item.className === "pending");
      const text = `${message.ns}: ${message.goal} ${OUTCOME_TEXT[message.outcome] || message.outcome}`;
      const state = message.outcome === "reached" ? "ok" : "error";
      if (row) this.update(row, state, text, message.message);
      else this.log(text, state, message.message);
      return true;
    }
    if (message.t === "tour") {
      if (message.ns === this.robot()) this.tour = message;
      const key = `tour|${message.ns}`;
      let row = this.rows.find((each) => each.key === key);
      if (!row || row.item.className !== "pending") row = this.log("", "pending");
      row.key = key;
      const state = message.state === "running" ? "pending" : message.state === "done" ? "ok" : "error";
      this.update(row, state, `${message.ns}: tour, ${message.state}`, message.message);
      this.onChange();
      return true;
    }
    if (message.t === "result" && ROBOT_COMMANDS.has(message.command)) {
      if (!message.ok) this.log(`${message.command} refused`, "error", message.message);
      if (!message.ok && message.command === "drive") this.onDriveEnded(true); // (stopped by another page)
      return true;
    }
    return false;
  }

  // ------------------------------------------------------------------ the log
  log(text, state, detail = "") {
    const item = document.createElement("li");
    const row = { key: null, item };
    this.rows.unshift(row);
    this.logList.prepend(item);
    while (this.rows.length > LOG_KEPT) this.rows.pop().item.remove();
    this.update(row, state, text, detail);
    return row;
  }

  update(row, state, text, detail = "") {
    row.item.className = state;
    row.item.textContent = `${new Date().toLocaleTimeString()} ${text}`;
    row.item.title = detail || "";
  }
}

function pose(x, y, th) {
  const round = (value, digits) => Number(value.toFixed(digits));
  return th === null || th === undefined ? [round(x, 3), round(y, 3)] : [round(x, 3), round(y, 3), round(th, 4)];
}

function poseText(x, y, th) {
  const heading = th === null || th === undefined ? "" : ` heading ${Math.round((th * 180) / Math.PI)}°`;
  return `(${x.toFixed(2)}, ${y.toFixed(2)})${heading}`;
}
