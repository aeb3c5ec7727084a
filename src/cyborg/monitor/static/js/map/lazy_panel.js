// The map panel, loaded after the tree's first paint so that it never delays it.
//
// The map's modules (js/map/*.js, a worker, canvases) are about as much code as the tree view;
// fetching and starting them before the tree is drawn made the first paint of a 1,000-node
// tree half again as slow. This stand-in takes the page's calls from the start and remembers
// what they said (the tree shown, whether the map can be seen, whether the socket is open, the
// last robots list and seat message); `load()` imports the real MapPanel and hands it that
// state. Until then no map opt-in is sent, so the monitor sends no map messages: it sends them
// all, from the map reference to the latest pose, when the panel opts in.

const LOAD_ANYWAY_MS = 1500; // a page that shows no tree (a robot without one) loads it anyway
const UNREADABLE_KEPT = 20;

export class LazyMapPanel {
  // `root`: the #map-view element; `options`: what MapPanel takes ({post, send}).
  constructor(root, options) {
    this.root = root;
    this.options = options;
    this.panel = null;
    this.loading = null;
    this.state = { tree: null, visible: null, connected: false, robots: null, seat: null, unreadable: [], goal: null };
    this.emptyListener = () => {};
    setTimeout(() => this.load(), LOAD_ANYWAY_MS);
  }

  // Imports the map's modules and starts the panel; later calls return the same promise.
  load() {
    if (this.loading === null) {
      this.loading = import("./map_panel.js").then(({ MapPanel }) => {
        const panel = new MapPanel(this.root, this.options);
        panel.onEmpty = this.emptyListener;
        const { tree, visible, connected, robots, seat, unreadable, goal } = this.state;
        if (tree !== null) panel.setTree(tree);
        if (goal !== null) panel.highlightGoal(goal);
        if (robots !== null) panel.receive(robots);
        if (seat !== null) panel.receive(seat);
        for (const [text, error] of unreadable) panel.unreadable(text, error);
        if (visible !== null) panel.setVisible(visible);
        if (connected) panel.connected();
        this.panel = panel;
        return panel;
      });
    }
    return this.loading;
  }

  // Whether there is no map to show: the layout listens (it shrinks an empty map).
  set onEmpty(listener) {
    this.emptyListener = listener;
    if (this.panel !== null) this.panel.onEmpty = listener;
  }

  get onEmpty() {
    return this.emptyListener;
  }

  // A message from the monitor: true when the map took it (before loading: none; the last
  // robots list and seat message are kept for the panel).
  receive(message) {
    if (this.panel !== null) return this.panel.receive(message);
    if (message && (message.t === "robots" || message.t === "seat")) this.state[message.t] = message;
    return false;
  }

  unreadable(text, error) {
    if (this.panel !== null) return this.panel.unreadable(text, error);
    if (this.state.unreadable.length < UNREADABLE_KEPT) this.state.unreadable.push([text, error]);
  }

  connected() {
    if (this.panel !== null) return this.panel.connected();
    this.state.connected = true;
  }

  setVisible(visible) {
    if (this.panel !== null) return this.panel.setVisible(visible);
    this.state.visible = visible;
  }

  setTree(ns) {
    if (this.panel !== null) return this.panel.setTree(ns);
    if (ns !== this.state.tree) this.state.goal = null;
    this.state.tree = ns;
  }

  // The goal names of the node selected in the tree (see MapPanel.highlightGoal).
  highlightGoal(names) {
    if (this.panel !== null) return this.panel.highlightGoal(names);
    this.state.goal = names;
  }
}
