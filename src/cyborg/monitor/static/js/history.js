// History: the ticks the monitor kept (its `history` message), shown one at a time with the
// slider under the tree; Live returns to the running tree. While it is shown, `state` is
// {ticks, position} and the tree is drawn from `at(count)` instead of the live model.

import { stateAt } from "./model.js";

const $ = (id) => document.getElementById(id);

export class History {
  // `onShow()` hears that the tick shown changed (or Live was chosen): redraw everything.
  constructor({ onShow, say }) {
    this.onShow = onShow;
    this.say = say;
    this.state = null;
    $("live").addEventListener("click", () => this.live());
    $("scrub").addEventListener("input", (event) => {
      if (!this.state) return;
      this.state.position = Number(event.target.value);
      this.show();
    });
  }

  // The monitor's history for the tree of structure `version`: shows its latest tick.
  start(message, version) {
    if (message.v !== version || !message.ticks.length) {
      this.say("no ticks recorded yet");
      return;
    }
    this.state = { ticks: message.ticks, position: message.ticks.length - 1 };
    const scrub = $("scrub");
    scrub.max = String(message.ticks.length - 1);
    scrub.value = scrub.max;
    scrub.disabled = false;
    $("live").disabled = false;
    this.show();
  }

  // The tree's state at the tick shown, for a tree of `count` nodes (stateAt in model.js).
  at(count) {
    return stateAt(this.state.ticks, this.state.position, count);
  }

  show() {
    const { ticks, position } = this.state;
    const [tick, time] = ticks[position];
    $("scrub-info").textContent = `tick ${tick} (t = ${time.toFixed(2)} s), ${ticks.length - 1 - position} ticks before the latest recorded`;
    this.onShow();
  }

  live() {
    this.state = null;
    $("scrub").disabled = true;
    $("live").disabled = true;
    $("scrub-info").textContent = "";
    this.onShow();
  }
}
