// Whether this page shows a played recording (`cyborg play`) rather than robots. The monitor's
// `player` message names the player while one is on the bus (js/player_bar.js draws its
// timeline). A recording cannot be acted on: the played topics tell what happened, and nothing
// on the bus carries out a goal, a STOP, driving, a mode's force or hold, or the tree's
// Run/Pause, hooks and breakpoints. So while a recording plays those controls are disabled,
// each tooltip ending in REPLAY_WHY, and a note above the tree says it in words. The player's
// own controls (pause, seek, step) stay. `cyborg play` moves only its own services under
// --namespace, never the played topics, so every tree and robot shown counts as played.
//
// One state for the page: app.js tells it the `player` messages (showReplay); the panels ask
// `replaying()` and hear changes through `onReplay(listener)`.

export const REPLAY_WHY = "off while a recording plays (cyborg play): it would act on no robot";

let player = null;
const listeners = new Set();

// Whether a played recording is shown now.
export function replaying() {
  return player !== null;
}

// The `player` message's player: its state, or null once none is on the bus.
export function showReplay(next) {
  const was = replaying();
  player = next ?? null;
  showNote();
  if (was !== replaying()) for (const listener of listeners) listener(replaying());
}

// Calls `listener(replaying)` whenever a recording starts or stops being shown; returns a
// function that stops it.
export function onReplay(listener) {
  listeners.add(listener);
  return () => listeners.delete(listener);
}

// Gives `element` (a control that is disabled while a recording plays) its tooltip: its own,
// with REPLAY_WHY after it while a recording is shown.
export function sayWhyOff(element) {
  if (element.dataset.ownTitle === undefined) element.dataset.ownTitle = element.title;
  const own = element.dataset.ownTitle;
  element.title = replaying() ? (own ? `${own} (${REPLAY_WHY})` : `Off: ${REPLAY_WHY}`) : own;
}

// The note above the tree (made on first use, after the page's banner).
function showNote() {
  let note = document.getElementById("replay-note");
  if (!note && !player) return;
  if (!note) {
    note = document.createElement("div");
    note.id = "replay-note";
    note.setAttribute("role", "status");
    document.getElementById("banner").after(note);
  }
  note.hidden = !player;
  if (!player) return;
  const file = player.file ? ` ${player.file}` : "";
  note.textContent = `▶ A played recording${file}, not a robot: STOP, goals, driving, modes and the tree's controls are off, as they would act on no robot. The bar under the tree plays, pauses and seeks it.`;
  note.title = REPLAY_WHY;
}
