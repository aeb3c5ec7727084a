// The Modes panel beside the tree: the mode machine of the shown tree runner (its `modes`
// message; hidden for a runner of a plain tree file). The machine is drawn as a list of states
// with their outgoing arrows, which stays readable however many modes there are: each state a
// box with the mode's name and its tree's title, the current one highlighted (and marked held
// while the operator holds it), the initial one marked; under each box the transitions that
// leave it, an arrow to the mode they enter labelled with their trigger (the condition cut
// short, its whole text in the tooltip; `event name`; `request`; `after 60 s`). Transitions
// from every mode (`from = "*"`) are drawn once, from "any mode", on top. Clicking an arrow's
// target scrolls to that state. Below: the last transitions (time, from → to, reason). What is
// wrong with the mode file or the machine (`problems`) is listed first, in red: a machine that
// cannot be drawn is never a blank panel. For the page that holds the control seat, each state
// other than the current one has Force and the panel has "Hold current mode"; other pages see
// them disabled, the tooltip saying why; so does every page while a recording plays
// (js/replay.js).

import { onReplay, replaying, REPLAY_WHY } from "./replay.js";

const $ = (id) => document.getElementById(id);
const LABEL_LIMIT = 36;
const ANY = "*";

// `text` cut to `limit` characters with an ellipsis.
export function shorten(text, limit = LABEL_LIMIT) {
  const value = String(text ?? "");
  return value.length <= limit ? value : `${value.slice(0, limit - 1)}…`;
}

// A transition's trigger as an arrow's label: [short, full].
export function triggerLabel(transition) {
  let full;
  if (transition.trigger === "condition") full = `when ${transition.when}`;
  else if (transition.trigger === "event") full = `event ${transition.event}`;
  else full = "request";
  if (transition.guard) full += ` if ${transition.guard}`;
  if (transition.reason) full += ` — “${transition.reason}”`;
  const core = transition.trigger === "condition" ? transition.when
    : transition.trigger === "event" ? `event ${transition.event}` : "request";
  return [shorten(core + (transition.guard ? " (guarded)" : "")), `transition ${transition.number}: ${full}`];
}

function element(tag, className, text) {
  const made = document.createElement(tag);
  if (className) made.className = className;
  if (text !== undefined) made.textContent = text;
  return made;
}

function seconds(value) {
  const number = Number(value);
  return Number.isFinite(number) ? `${number.toFixed(number < 10 ? 2 : 1)} s` : "–";
}

export class ModesPanel {
  // `send(command)` sends a command and says its result.
  constructor({ send }) {
    this.send = send;
    this.modes = null;
    this.ns = null;
    this.seat = { may_control: false, control: false };
    this.alive = false;
    this.drawnMachine = "";
    onReplay(() => this.controls());
    $("mode-hold").addEventListener("click", () => {
      if (this.modes) this.send({ t: "mode_hold", ns: this.ns, held: !this.modes.held });
    });
    $("modes-states").addEventListener("click", (event) => {
      const force = event.target.closest("button[data-force]");
      if (force) {
        this.send({ t: "mode_force", ns: this.ns, mode: force.dataset.force, reason: "forced from the monitor" });
        return;
      }
      const jump = event.target.closest("[data-goto]");
      if (jump) this.reveal(jump.dataset.goto);
    });
  }

  // The monitor's `modes` message for the tree runner `ns`: its machine, or null when none.
  show(ns, modes) {
    this.ns = ns;
    this.modes = modes;
    $("modes").hidden = !modes;
    if (!modes) {
      this.drawnMachine = "";
      return;
    }
    this.problems(modes.problems || []);
    const key = JSON.stringify(modes.machine);
    if (key !== this.drawnMachine) {
      this.drawnMachine = key;
      this.draw(modes.machine);
    }
    this.current();
    this.recent(modes.recent || []);
    this.controls();
  }

  // The mode of the tree the view shows, named above the tree: the current mode when its tree
  // is the one shown, else the mode whose tree has `title` (a switch on its way).
  modeOfTree(title) {
    const machine = this.modes && this.modes.machine;
    if (!machine) return null;
    const current = machine.modes.find((mode) => mode.name === this.modes.mode);
    if (current && current.title === title) return current.name;
    const other = machine.modes.find((mode) => mode.title === title);
    return other ? other.name : null;
  }

  // Over the tree: which mode's tree the view shows (`title`; `drawn`: a tree is drawn).
  showTreeMode(title, drawn) {
    const badge = $("tree-mode");
    badge.hidden = !this.modes || !drawn;
    if (badge.hidden) return;
    const shown = this.modeOfTree(title);
    const switching = shown !== this.modes.mode;
    badge.textContent = `mode ${shown ?? "?"} · ${title}${switching ? ` (switching to ${this.modes.mode})` : ""}`;
    badge.dataset.mode = shown ?? "";
    badge.classList.toggle("switching", switching);
  }

  problems(lines) {
    const list = $("modes-problems");
    list.replaceChildren(...lines.map((line) => element("li", "", line)));
    list.hidden = !lines.length;
  }

  draw(machine) {
    const states = $("modes-states");
    if (!machine) {
      states.replaceChildren(element("li", "hint", "The machine cannot be drawn (see the problems above)."));
      return;
    }
    const items = [];
    const fromAny = machine.transitions.filter((t) => t.from.includes(ANY));
    if (fromAny.length) items.push(this.state({ name: ANY, title: "every mode but the one entered" }, fromAny, null));
    for (const mode of machine.modes) {
      const leaving = machine.transitions.filter((t) => t.from.includes(mode.name));
      items.push(this.state(mode, leaving, machine.initial));
    }
    states.replaceChildren(...items);
  }

  // One state's box and its outgoing arrows.
  state(mode, leaving, initial) {
    const item = element("li", mode.name === ANY ? "mode-state any" : "mode-state");
    item.dataset.mode = mode.name;
    const box = element("div", "mode-box");
    const name = element("span", "mode-name", mode.name === ANY ? "any mode" : shorten(mode.name, 28));
    name.title = mode.name === ANY ? "transitions from every mode (from = \"*\")" : mode.name;
    box.append(name);
    if (mode.name === initial) box.append(element("span", "mode-tag", "initial"));
    const title = element("span", "mode-tree", shorten(mode.title, 32));
    title.title = `tree: ${mode.title}${mode.tree && mode.tree !== mode.title ? ` (id ${mode.tree})` : ""}${mode.description ? ` — ${mode.description}` : ""}`;
    box.append(title);
    if (mode.name !== ANY) {
      const force = element("button", "mode-force", "Force");
      force.dataset.force = mode.name;
      box.append(force);
    }
    item.append(box);
    const arrows = element("ul", "mode-arrows");
    for (const transition of leaving) arrows.append(this.arrow(transition.to, ...triggerLabel(transition)));
    if (mode.max_time !== null && mode.max_time !== undefined && mode.then) {
      arrows.append(this.arrow(mode.then, `after ${mode.max_time} s`, `max_time: after ${mode.max_time} s in ${mode.name}, to ${mode.then}`));
    }
    if (arrows.children.length) item.append(arrows);
    return item;
  }

  arrow(target, label, full) {
    const row = element("li", "mode-arrow");
    row.title = full;
    const goto = element("a", "mode-target", shorten(target, 24));
    goto.dataset.goto = target;
    goto.href = "#";
    goto.addEventListener("click", (event) => event.preventDefault());
    row.append(element("span", "arrow-head", "→ "), goto, element("span", "mode-trigger", label));
    return row;
  }

  reveal(name) {
    const item = $("modes-states").querySelector(`li.mode-state[data-mode="${CSS.escape(name)}"]`);
    if (!item) return;
    item.scrollIntoView({ block: "nearest" });
    item.classList.add("flash");
    setTimeout(() => item.classList.remove("flash"), 900);
  }

  current() {
    const { mode, held } = this.modes;
    for (const item of $("modes-states").querySelectorAll("li.mode-state")) {
      const here = item.dataset.mode === mode;
      item.classList.toggle("current", here);
      item.classList.toggle("held", here && held);
    }
    $("modes-current").textContent = mode ? `${mode}${held ? " · held" : ""}` : "";
    const hold = $("mode-hold");
    hold.textContent = held ? "Release hold" : "Hold current mode";
    hold.setAttribute("aria-pressed", String(Boolean(held)));
    $("mode-held").textContent = held ? `${mode} is held: only a force leaves it` : "";
  }

  recent(transitions) {
    const rows = transitions.slice().reverse().map((t) => {
      const row = element("li", `trigger-${t.trigger}`);
      row.append(element("span", "when", seconds(t.time)), element("b", "", ` ${t.from} → ${t.to} `), element("span", "why", t.reason));
      row.title = `${t.trigger}${t.number ? ` (transition ${t.number})` : ""} at t = ${seconds(t.time)}: ${t.reason}`;
      return row;
    });
    $("modes-recent").replaceChildren(...(rows.length ? rows : [element("li", "hint", "none since the monitor started")]));
  }

  // The page's control seat (its `seat` message) and whether the runner is there.
  setSeat(seat) {
    this.seat = seat;
    this.controls();
  }

  setAlive(alive) {
    this.alive = alive;
    this.controls();
  }

  controls() {
    if (!this.modes) return;
    const why = replaying() ? `Force and hold are ${REPLAY_WHY}` : !this.seat.may_control
      ? "View only: modes are forced from the monitor's own page on its machine, or with its token"
      : !this.seat.control ? "Another page has control (or none was taken): take control to force or hold a mode"
      : !this.alive ? "The tree runner is not on the bus" : "";
    const hold = $("mode-hold");
    hold.disabled = Boolean(why);
    hold.title = why || "Hold the current mode: no condition, event, request or time limit leaves it; only a force does";
    for (const button of $("modes-states").querySelectorAll("button[data-force]")) {
      const here = button.dataset.force === this.modes.mode;
      button.disabled = Boolean(why) || here;
      button.title = why || (here ? "This is the current mode" : `Enter ${button.dataset.force} now, past transitions, guards, dwell and hold`);
    }
  }
}
