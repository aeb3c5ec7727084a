// What the page shows around the tree about the runner, the seat and the connection: the
// toolbar (Run/Pause, who holds the control seat, Take control, where a breakpoint waits, a tree
// paused for a manual goal from the map), the banner (connection lost, a problem with the tree,
// the runner gone), the tree selector and the message line. Each function redraws its part
// from app.js's `page` state and the tree model; none keeps state of its own.

const $ = (id) => document.getElementById(id);

export function showToolbar(page, model) {
  const seat = page.seat;
  const mayAct = seat.control && page.alive;
  for (const button of document.querySelectorAll("button.control")) button.disabled = !mayAct;
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

// The tree selector: every tree runner the monitor follows, the shown one selected.
export function showTrees(page) {
  const select = $("robot");
  const current = page.ns;
  select.innerHTML = "";
  for (const robot of page.robots) {
    const option = document.createElement("option");
    option.value = robot.ns;
    option.textContent = `${robot.ns}${robot.title ? ` — ${robot.title}` : ""}${robot.alive ? "" : " (offline)"}`;
    select.append(option);
  }
  if (current) select.value = current;
}

export function say(text, error = false) {
  const el = $("message");
  el.textContent = text;
  el.className = error ? "error" : "";
}
