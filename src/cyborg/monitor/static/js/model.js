// What the page knows about the watched tree: structure, display codes, active path, hooks,
// timings. Messages from the monitor are applied here; the view reads it.
//
// A display code is the node's last status (0 never ran, 1 success, 2 failure, 3 running,
// 4 error) plus 8 when it ran in the latest tick. Nodes are addressed by id; the server's
// deltas use pre-order indices, which `ids` maps back.

export class TreeModel {
  constructor() {
    this.reset(null, null);
  }

  reset(version, root) {
    this.version = version;
    this.root = root;
    this.ids = [];
    this.byId = new Map();
    this.parent = new Map();
    this.level = new Map(); // id -> its distance from the root (the root: 0)
    if (root) {
      const stack = [[root, null]];
      while (stack.length) {
        const [node, parent] = stack.pop();
        this.byId.set(node.id, node);
        this.parent.set(node.id, parent);
        this.level.set(node.id, parent === null ? 0 : this.level.get(parent) + 1);
        this.ids.push(node.id);
        for (let i = node.children.length - 1; i >= 0; i--) stack.push([node.children[i], node.id]);
      }
    }
    this.indexOf = new Map(this.ids.map((id, index) => [id, index]));
    this.codes = new Uint8Array(this.ids.length);
    this.active = [];
    this.activeSet = new Set();
    this.seq = -1;
    this.tick = 0;
    this.time = 0;
    this.duration = 0;
    this.rootStatus = 0;
    this.timing = new Map();
    this.services = new Map(); // composite id -> its services' states, from `services` messages
    this.servicesOn = new Set(); // composites with a service running
    this.servicesTime = 0; // the tree's clock when the runner took the states
  }

  code(id) {
    const index = this.indexOf.get(id);
    return index === undefined ? 0 : this.codes[index];
  }

  // A full snapshot; returns true when the active path changed.
  applySnapshot(message) {
    this.codes = Uint8Array.from(message.codes);
    this.seq = message.seq;
    this.header(message);
    return this.setActive(message.act);
  }

  // A delta frame: returns the ids whose look changed, or null if the frame is stale.
  applyFrame(message) {
    if (message.v !== this.version || message.seq <= this.seq) return null;
    this.seq = message.seq;
    this.header(message);
    const changed = new Set();
    const pairs = message.ch;
    for (let i = 0; i < pairs.length; i += 2) {
      this.codes[pairs[i]] = pairs[i + 1];
      changed.add(this.ids[pairs[i]]);
    }
    if (message.act) {
      const before = this.activeSet;
      if (this.setActive(message.act)) {
        for (const id of before) changed.add(id);
        for (const id of this.activeSet) changed.add(id);
        changed.activeChanged = true;
      }
    }
    return changed;
  }

  header(message) {
    this.tick = message.tick;
    this.time = message.time;
    this.duration = message.dur;
    this.rootStatus = message.root;
  }

  setActive(indices) {
    const ids = indices.map((index) => this.ids[index]).filter((id) => id !== undefined);
    const same = ids.length === this.active.length && ids.every((id, i) => id === this.active[i]);
    this.active = ids;
    this.activeSet = new Set(ids);
    return !same;
  }

  applyTiming(rows) {
    for (const row of rows) {
      const id = this.ids[row[0]];
      if (id !== undefined) {
        this.timing.set(id, { calls: row[1], last: row[2], mean: row[3], min: row[4], max: row[5], changes: row[6], since: row[7] });
      }
    }
  }

  // A `services` message (the states of the services on composites); returns the composites
  // whose badge changed (running or not), or null when the message is for another tree.
  applyServices(message) {
    if (message.v !== this.version) return null;
    const services = new Map();
    const on = new Set();
    for (const state of message.s) {
      if (!this.byId.has(state.id)) continue;
      if (!services.has(state.id)) services.set(state.id, []);
      services.get(state.id).push(state);
      if (state.active) on.add(state.id);
    }
    const changed = new Set([...on].filter((id) => !this.servicesOn.has(id)));
    for (const id of this.servicesOn) if (!on.has(id)) changed.add(id);
    this.services = services;
    this.servicesOn = on;
    this.servicesTime = message.time;
    return changed;
  }

  ancestors(id) {
    const found = [];
    for (let up = this.parent.get(id); up; up = this.parent.get(up)) found.push(up);
    return found;
  }
}

// The state of the tree at one tick of the history: codes and active path rebuilt from the
// recorded ticks (each entry: [tick, time, ms, root, visited indices, statuses, active]).
export function stateAt(ticks, position, size) {
  const codes = new Uint8Array(size);
  for (let i = 0; i <= position; i++) {
    const [, , , , visited, statuses] = ticks[i];
    for (let j = 0; j < visited.length; j++) codes[visited[j]] = statuses[j];
  }
  const [tick, time, duration, root, visited, , active] = ticks[position];
  for (const index of visited) codes[index] |= 8;
  return { tick, time, duration, root, codes, active };
}
