// The red "Stopped — Resume" banner: one row per tree runner that a STOP halted (the map's
// STOP, Space or Escape on the map, `cyborg bt stop`; its latched `stopped`, in each tree of
// the monitor's `robots` message), shown on every page, one opened later included, until the
// tree runs again. The row names the robot the tree drives (in its colour) and the tree; its
// Resume enables the tree (the `enable` command, as Run does: the tree starts afresh from its
// root and may send the robot on at once). Resume needs the control seat; without it, or while
// a played recording is shown (js/replay.js), it is disabled and its tooltip says why. Resumed
// from anywhere (another page, another monitor, `cyborg bt enable`), the row goes.

import { colourOf, robotOfTree } from "./robots.js";
import { onReplay, replaying, REPLAY_WHY } from "./replay.js";

const VIEW_ONLY = "view only: open the monitor on the robot's machine, or with its token";
const NO_SEAT = "take control (top right) to resume";
const RESUME_TIP = "Run the tree again, from its start (it may send the robot on at once)";

export class StopBanner {
  // `send(command)`: sends a command and says its result.
  constructor({ send }) {
    this.send = send;
    this.trees = []; // the stopped trees: [{ns, title}]
    this.seat = { may_control: false, control: false };
    this.root = document.createElement("div");
    this.root.id = "stopped";
    this.root.setAttribute("role", "alert");
    this.root.hidden = true;
    document.getElementById("banner").after(this.root);
    this.root.addEventListener("click", (event) => {
      const button = event.target.closest("button[data-resume]");
      if (button && !button.disabled) this.send({ t: "enable", on: true, ns: button.dataset.resume });
    });
    onReplay(() => this.draw());
  }

  // A message from the monitor: `robots` (the trees, stopped or not) and `seat` are read, never
  // taken from the rest of the page.
  receive(message) {
    if (message.t === "robots") {
      const stopped = (message.robots || []).filter((tree) => tree.stopped === true && tree.alive);
      this.trees = stopped.map((tree) => ({ ns: tree.ns, title: tree.title || "" }));
      this.draw();
    } else if (message.t === "seat") {
      this.seat = { may_control: !!message.may_control, control: !!message.control };
      this.draw();
    }
  }

  // Whether the tree `ns` is stopped now.
  stopped(ns) {
    return this.trees.some((tree) => tree.ns === ns);
  }

  draw() {
    const why = replaying() ? REPLAY_WHY : !this.seat.may_control ? VIEW_ONLY : !this.seat.control ? NO_SEAT : "";
    const rows = this.trees.map((tree) => {
      const row = document.createElement("div");
      const robot = robotOfTree(tree.ns);
      const name = document.createElement("b");
      name.textContent = `■ ${robot || tree.ns} stopped`;
      if (robot) name.style.setProperty("--robot", colourOf(robot));
      const what = document.createElement("span");
      what.textContent = ` — the tree ${tree.ns}${tree.title ? ` (${tree.title})` : ""} is halted and sends no goal until resumed `;
      const resume = document.createElement("button");
      resume.dataset.resume = tree.ns;
      resume.textContent = "Resume";
      resume.disabled = !!why;
      resume.title = why ? `${RESUME_TIP} (${why})` : RESUME_TIP;
      row.append(name, what, resume);
      return row;
    });
    this.root.replaceChildren(...rows);
    this.root.hidden = rows.length === 0;
  }
}
