// Driving the robot by hand from the map: the arrow keys or WASD while the map has focus, or an
// on-screen joystick (pointer events, so a thumb on a phone works), and Space or Escape to stop.
//
// While a key or the joystick is held, the page sends {t: "drive", ns, vx, wz} ten times a
// second (the robot stops by itself 0.5 s after the last one, its deadman); letting go sends
// one zero. Speeds are in m/s and rad/s, at most SPEED and TURN at full deflection (the robot's
// own limits, TELEOP_MAX_SPEED and TELEOP_MAX_TURN_RATE, which the monitor and the robot
// enforce again); the keys drive at KEY_SHARE of that, Shift at full. Driving needs the seat,
// as every action but Stop does; the monitor pauses the robot's tree on the first move. A STOP
// (from this page, or a refused drive: another page stopped the robot) ends the drive: the key
// or the joystick must be pressed again, a key's auto-repeat does not start it again.

const PERIOD_MS = 100;
const SPEED = 0.5; // m/s
const TURN = 1.0; // rad/s
const KEY_SHARE = 0.6;
const KEYS = {
  ArrowUp: [1, 0], KeyW: [1, 0], ArrowDown: [-1, 0], KeyS: [-1, 0],
  ArrowLeft: [0, 1], KeyA: [0, 1], ArrowRight: [0, -1], KeyD: [0, -1],
};
const TYPING = new Set(["INPUT", "SELECT", "TEXTAREA"]);

export class Driver {
  // `root`: #map-view; `actions`: MapActions (who may act, on which robot, and Stop);
  // `post(command)`: send without an answer.
  constructor(root, { actions, post }) {
    this.actions = actions;
    this.post = post;
    this.keys = new Set(); // codes of the drive keys held
    this.shift = false;
    this.stick = null; // [x, y] in -1..1 (y forward) while the joystick is held
    this.timer = null;
    this.target = null; // the robot being driven
    actions.onDriveEnded = (zero) => this.release(zero);
    this.toggle = root.querySelector("#map-drive");
    this.pad = root.querySelector("#map-joystick");
    this.knob = this.pad.querySelector(".knob");
    this.toggle.addEventListener("click", () => {
      const on = this.pad.hidden;
      this.pad.hidden = !on;
      this.toggle.setAttribute("aria-pressed", String(on));
    });
    root.addEventListener("keydown", (event) => this.keyDown(event));
    root.addEventListener("keyup", (event) => this.keyUp(event));
    root.addEventListener("focusout", (event) => {
      if (!root.contains(event.relatedTarget)) this.release();
    });
    this.joystick();
  }

  keyDown(event) {
    if (TYPING.has(event.target.tagName)) return;
    if (event.code === "Escape" || (event.code === "Space" && event.target.tagName !== "BUTTON")) {
      event.preventDefault();
      this.release(false);
      this.actions.stop();
      return;
    }
    if (!(event.code in KEYS)) return;
    event.preventDefault(); // no scrolling with the arrows
    if (!this.actions.canAct || (event.repeat && this.timer === null)) return;
    this.shift = event.shiftKey;
    this.keys.add(event.code);
    this.start();
  }

  keyUp(event) {
    if (!this.keys.delete(event.code)) return;
    this.shift = event.shiftKey;
    if (!this.active) this.finish();
  }

  joystick() {
    const pad = this.pad;
    const place = (event) => {
      const box = pad.getBoundingClientRect();
      const radius = box.width / 2;
      let x = (event.clientX - box.left - radius) / radius;
      let y = -(event.clientY - box.top - radius) / radius;
      const length = Math.hypot(x, y);
      if (length > 1) { x /= length; y /= length; }
      this.stick = [x, y];
      this.knob.style.transform = `translate(${x * radius}px, ${-y * radius}px)`;
    };
    pad.addEventListener("pointerdown", (event) => {
      if (!this.actions.canAct) return;
      event.preventDefault();
      try {
        pad.setPointerCapture(event.pointerId);
      } catch {
        // a synthetic pointer: it drives without capture
      }
      place(event);
      this.start();
    });
    pad.addEventListener("pointermove", (event) => { if (this.stick) place(event); });
    const letGo = () => {
      if (!this.stick) return;
      this.stick = null;
      this.knob.style.transform = "";
      if (!this.active) this.finish();
    };
    pad.addEventListener("pointerup", letGo);
    pad.addEventListener("pointercancel", letGo);
  }

  get active() {
    return this.keys.size > 0 || this.stick !== null;
  }

  // {vx, wz} for what is held now.
  command() {
    if (this.stick) return { vx: round(this.stick[1] * SPEED), wz: round(-this.stick[0] * TURN) };
    let forward = 0, turn = 0;
    for (const code of this.keys) {
      forward += KEYS[code][0];
      turn += KEYS[code][1];
    }
    const share = this.shift ? 1 : KEY_SHARE;
    return { vx: round(Math.sign(forward) * SPEED * share), wz: round(Math.sign(turn) * TURN * share) };
  }

  start() {
    if (this.timer !== null) return;
    this.target = this.actions.robot();
    this.send();
    this.timer = setInterval(() => this.send(), PERIOD_MS);
  }

  send() {
    if (!this.active || !this.actions.canAct || this.actions.robot() !== this.target) {
      this.finish();
      return;
    }
    this.post({ t: "drive", ns: this.target, ...this.command() });
  }

  // Stops sending; one zero unless `zero` is false (a Stop follows, which stops the robot).
  finish(zero = true) {
    if (this.timer === null) return;
    clearInterval(this.timer);
    this.timer = null;
    if (zero && this.target) this.post({ t: "drive", ns: this.target, vx: 0, wz: 0 });
    this.target = null;
  }

  release(zero = true) {
    this.keys.clear();
    this.stick = null;
    this.knob.style.transform = "";
    this.finish(zero);
  }
}

function round(value) {
  return Math.round(value * 1000) / 1000 || 0;
}
