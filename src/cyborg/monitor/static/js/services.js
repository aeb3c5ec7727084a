// The services on composites (docs/services.md): the badge a composite carrying services wears
// in the tree, and the list of its services in the node's details panel.
//
// Which services a composite carries comes with the structure (`node.services`: name,
// declaration, interval, ...); what they do comes in `services` messages, at most four a second,
// which the model keeps (TreeModel.applyServices). The badge is drawn with the node (TreeView's
// `badge` option) and only its "on" class changes when a message comes, never in the per-tick
// paint.

import { escapeHtml } from "./tree_view.js";

const PILL_WIDTH = 30;
const PILL_HEIGHT = 16;
let shown = "";

// The badge of `node` drawn `width` wide: a pill over its top-right corner with a gear and the
// number of services, "on" while one of them runs; "" for a node without services.
export function badgeMarkup(node, width, on) {
  const services = node.services;
  if (!services || !services.length) return "";
  const names = services.map((service) => service.declaration || service.name).join("; ");
  return `<g class="svc${on ? " on" : ""}" transform="translate(${width - PILL_WIDTH + 6},${-PILL_HEIGHT / 2})">` +
    `<title>services: ${escapeHtml(names)}</title>` +
    `<rect width="${PILL_WIDTH}" height="${PILL_HEIGHT}" rx="${PILL_HEIGHT / 2}"></rect>` +
    `<text x="${PILL_WIDTH / 2}" y="${PILL_HEIGHT / 2 + 1}">⚙${services.length}</text></g>`;
}

// The details panel's list of the services on `node`: each with its declaration, whether it
// runs, when it last ran (on the tree's clock, and how long ago), how often, what it wrote and
// its last error. Hidden for a node without services.
export function showServices(node, model) {
  const section = document.getElementById("node-services");
  const declared = node.services || [];
  section.hidden = !declared.length;
  if (!declared.length) {
    section.innerHTML = shown = "";
    return;
  }
  const states = model.services.get(node.id) || [];
  const now = Math.max(model.time, model.servicesTime);
  let html = declared.map((service) => {
    const state = states.find((candidate) => candidate.name === service.name);
    const rows = [["declared", service.declaration || service.name], ["every", `${service.interval} s${service.deviation ? ` ± ${service.deviation} s` : ""}`]];
    if (!state) rows.push(["state", "no news yet"]);
    else {
      rows.push(["state", state.active ? "running" : "stopped"]);
      rows.push(["last ran", state.last === null ? "never" : `t = ${state.last.toFixed(2)} s (${ago(now - state.last)})`]);
      rows.push(["runs", String(state.runs)]);
      for (const [key, value] of state.wrote) rows.push([`wrote ${key}`, value]);
    }
    const error = state && state.error ? `<p class="svc-error">${escapeHtml(state.error)}</p>` : "";
    const on = state && state.active ? " on" : "";
    return `<div class="svc-item${on}" data-service="${escapeHtml(service.name)}"><h5>⚙ ${escapeHtml(service.name)}</h5>` +
      `<table class="facts"><tbody>${rows.map(([key, value]) => `<tr><td>${escapeHtml(key)}</td><td>${escapeHtml(value)}</td></tr>`).join("")}</tbody></table>${error}</div>`;
  }).join("");
  html = `<h4>Services</h4>${html}`;
  if (html !== shown) section.innerHTML = shown = html;
}

function ago(seconds) {
  if (!(seconds > 0)) return "just now";
  if (seconds < 60) return `${seconds.toFixed(1)} s ago`;
  return `${Math.floor(seconds / 60)} min ${Math.round(seconds % 60)} s ago`;
}
