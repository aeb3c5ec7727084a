// The side panels: the selected node (facts, its services, timing, hook, control buttons) and
// the live blackboard table.

import { showServices } from "./services.js";
import { countBelow, escapeHtml } from "./tree_view.js";

const STATUS_NAMES = ["never ran", "success", "failure", "running", "error"];

export function showNode(model, id, hooks) {
  const body = document.getElementById("inspector-body");
  const empty = document.getElementById("inspector-empty");
  const node = id ? model.byId.get(id) : null;
  body.hidden = !node;
  empty.hidden = !!node;
  if (!node) return;
  document.getElementById("node-label").textContent = node.label || node.name;
  const code = model.code(id);
  const facts = [
    ["name", node.name],
    ["id", id],
    ["category", node.category],
    ["nesting", `${node.depth} (subtree depth)`],
    ["status", `${STATUS_NAMES[code & 7]}${code & 8 ? " (this tick)" : code & 7 ? " (last time)" : ""}`],
    ["children", node.children.length ? `${node.children.length} (${countBelow(node)} below)` : "none"],
  ];
  for (const [key, value] of Object.entries(node.properties || {})) facts.push([key, JSON.stringify(value)]);
  document.getElementById("node-facts").innerHTML = rows(facts);
  showServices(node, model);
  const timing = model.timing.get(id);
  document.getElementById("node-timing").innerHTML = timing
    ? rows([
        ["ticks", String(timing.calls)],
        ["last", ms(timing.last)],
        ["mean", ms(timing.mean)],
        ["min / max", `${ms(timing.min)} / ${ms(timing.max)}`],
        ["changes", `${timing.changes} status changes`],
        ["since", `${STATUS_NAMES[code & 7]} since t = ${timing.since.toFixed(2)} s`],
      ])
    : rows([["ticks", "not timed yet"]]);
  const hook = hooks.get(id);
  document.getElementById("node-hook").textContent = hook
    ? `${hook.mode}${hook.mode === "breakpoint" ? "" : ` → ${hook.status}`}${hook.owner ? ` (set by ${hook.owner})` : " (kept)"}`
    : "no hook";
}

function rows(pairs) {
  return pairs.map(([key, value]) => `<tr><td>${escapeHtml(key)}</td><td>${escapeHtml(value)}</td></tr>`).join("");
}

function ms(value) {
  if (value === null || value === undefined || Number.isNaN(value)) return "–";
  return value < 1 ? `${(value * 1000).toFixed(1)} µs` : `${value.toFixed(2)} ms`;
}

// ------------------------------------------------------------------ blackboard
// Scope and key take the width of their text, the value the rest of the row, cut to one line;
// each cell's whole text is its title (hover), and a click on a row shows it all (again: cut).
let previous = new Map();
const opened = new Set(); // rows shown whole, by scope and key

document.getElementById("bb-rows").addEventListener("click", (event) => {
  const row = event.target.closest("tr[data-row]");
  if (!row) return;
  const open = !opened.delete(row.dataset.row);
  if (open) opened.add(row.dataset.row);
  row.classList.toggle("open", open);
});

// `labelOf(id)` names a node for the "node" scope rows.
export function showBlackboard(data, filter, labelOf) {
  const entries = [];
  const add = (scope, values) => {
    for (const [key, value] of Object.entries(values || {})) entries.push([scope, key, JSON.stringify(value)]);
  };
  add("global", data.global);
  for (const [tree, values] of Object.entries(data.trees || {})) add(`tree ${tree}`, values);
  for (const [node, values] of Object.entries(data.nodes || {})) add(`node ${labelOf(node)}`, values);
  const needle = filter.trim().toLowerCase();
  const shown = needle ? entries.filter((row) => row.join(" ").toLowerCase().includes(needle)) : entries;
  const now = new Map(entries.map(([scope, key, value]) => [`${scope}\u0000${key}`, value]));
  document.getElementById("bb-rows").innerHTML = shown
    .map(([scope, key, value]) => {
      const row = `${scope}\u0000${key}`;
      const classes = [previous.size && previous.get(row) !== value ? "changed" : "", opened.has(row) ? "open" : ""].join(" ").trim();
      const cut = (text) => `<span class="cut" title="${escapeHtml(text)}">${escapeHtml(text)}</span>`;
      return `<tr data-row="${escapeHtml(row)}"${classes ? ` class="${classes}"` : ""}>` +
        `<td class="bb-scope">${cut(scope)}</td><td class="bb-key">${cut(key)}</td>` +
        `<td class="bb-value" title="${escapeHtml(value)}">${escapeHtml(value)}</td></tr>`;
    })
    .join("");
  previous = now;
}
