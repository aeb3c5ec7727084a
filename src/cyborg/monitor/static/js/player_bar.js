// The timeline of a played recording (`cyborg play`): while the monitor follows a player (its
// `player` message), the bar under the tree shows the whole recording instead of the ticks the
// monitor kept — the file, the position of the duration as m:ss, pause/resume, step, and a
// slider to seek. Dragging shows the time under the thumb and seeks on release; the keyboard
// seeks too (arrows 5 s, with Shift 1 s, Page Up/Down 30 s, Home and End). The commands need
// the control seat: a page without it sees the position with its controls disabled, their
// tooltip saying why. `onJump()` hears that the played time jumped (a seek, a loop) or a player
// appeared, so the history of ticks shown before (another timeline) is left.

const $ = (id) => document.getElementById(id);
const HISTORY_CONTROLS = ["history", "scrub", "live", "scrub-info"];
const KEY_SECONDS = { ArrowLeft: -5, ArrowDown: -5, ArrowRight: 5, ArrowUp: 5, PageDown: -30, PageUp: 30 };
const TITLES = {
  "player-pause": "Pause or resume the recording (the player's pause service)",
  "player-step": "Play the next message of the recording, then stay paused",
  "player-scrub": "Drag to a time of the recording and let go to seek there (keys: arrows 5 s, Shift+arrows 1 s, Page Up/Down 30 s, Home, End)",
};

// Seconds as m:ss (h:mm:ss from an hour on), whole seconds rounded down.
export function clock(seconds) {
  const whole = Math.max(0, Math.floor(Number(seconds) || 0));
  const hours = Math.floor(whole / 3600);
  const minutes = Math.floor((whole % 3600) / 60);
  const secs = String(whole % 60).padStart(2, "0");
  return hours ? `${hours}:${String(minutes).padStart(2, "0")}:${secs}` : `${minutes}:${secs}`;
}

export class PlayerBar {
  // `send(command)` sends a command and says its result; `onJump()` as above.
  constructor({ send, onJump }) {
    this.send = send;
    this.onJump = onJump;
    this.player = null;
    this.seat = { may_control: false, control: false };
    this.dragging = false;
    const scrub = $("player-scrub");
    scrub.addEventListener("pointerdown", () => { this.dragging = true; });
    scrub.addEventListener("input", () => { this.dragging = true; this.showTime(Number(scrub.value), true); });
    scrub.addEventListener("change", () => this.seek(Number(scrub.value)));
    scrub.addEventListener("keydown", (event) => this.key(event));
    $("player-pause").addEventListener("click", () => {
      if (this.player) this.send({ t: "player_pause", paused: !this.player.paused });
    });
    $("player-step").addEventListener("click", () => this.send({ t: "player_step" }));
  }

  // The monitor's `player` message: the player's state, or null when none is on the bus.
  show(player) {
    const was = this.player;
    this.player = player;
    $("player-bar").hidden = !player;
    for (const id of HISTORY_CONTROLS) $(id).hidden = Boolean(player);
    if (!player) return;
    if (!was || was.jumps !== player.jumps) this.onJump();
    const scrub = $("player-scrub");
    scrub.max = String(player.duration);
    if (!this.dragging) {
      scrub.value = String(player.position);
      this.showTime(player.position, false);
    }
    $("player-file").textContent = player.file + (player.rate !== 1 ? ` x${player.rate}` : "") + (player.finished ? " · ended" : "");
    $("player-file").title = `played by ${player.ns}/player`;
    const pause = $("player-pause");
    pause.textContent = player.paused ? "▶ Play" : "❚❚ Pause";
    pause.setAttribute("aria-pressed", String(player.paused));
    this.controls();
  }

  // The page's control seat (its `seat` message): whether the controls may be used.
  setSeat(seat) {
    this.seat = seat;
    this.controls();
  }

  controls() {
    const why = !this.seat.may_control
      ? "View only: the recording is scrubbed from the monitor's own page on its machine, or with its token"
      : !this.seat.control ? "Another page has control (or none was taken): take control to scrub the recording" : "";
    for (const [id, title] of Object.entries(TITLES)) {
      $(id).disabled = Boolean(why) || !this.player;
      $(id).title = why || title;
    }
    $("player-bar").title = why;
  }

  showTime(position, dragged) {
    const text = `${clock(position)} / ${clock(this.player ? this.player.duration : 0)}`;
    $("player-time").textContent = dragged ? `→ ${text}` : text;
    $("player-scrub").setAttribute("aria-valuetext", text);
  }

  key(event) {
    if (!this.player) return;
    let target = null;
    if (event.key in KEY_SECONDS) target = this.player.position + (event.shiftKey ? Math.sign(KEY_SECONDS[event.key]) : KEY_SECONDS[event.key]);
    else if (event.key === "Home") target = 0;
    else if (event.key === "End") target = this.player.duration;
    if (target === null) return;
    event.preventDefault();
    this.seek(target);
  }

  seek(position) {
    this.dragging = false;
    if (!this.player) return;
    const target = Math.min(Math.max(position, 0), this.player.duration);
    $("player-scrub").value = String(target);
    this.showTime(target, false);
    this.send({ t: "player_seek", position: target });
  }
}
