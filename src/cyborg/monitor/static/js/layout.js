// The page's main area: the tree view | a draggable splitter | the map panel | the details
// (node inspector and blackboard).
//
// - The splitter shares the width between tree and map (drag it, or focus it and use the arrow
//   keys; double-click: half and half). The share is kept in localStorage.
// - Either panel can be maximised with its ⤢ button: it takes the whole width of the page (the
//   other panel and the details are hidden until restored); kept in localStorage too. A map
//   maximised on a page without a map yet shows the split until one arrives.
// - Under 700 px wide (phones), tabs replace the split: Map | Tree | Details, one at a time,
//   Map first; the toolbar keeps the robot, Run, the control seat and a ☰ button that opens
//   the rest of the tools (draw depth, fit, search, save) on rows of their own.
//
// - Until a map arrives (a monitor or robot without maps), the map is a narrow column saying
//   "no map yet" and the tree keeps the room; the split applies once there is a map.
//
// Only classes, data attributes and the panels' flex change here; monitor.css does the rest.
// `onMapShown(on)` hears whether the map can be seen, so the page asks the monitor for map
// data only then.

const $ = (id) => document.getElementById(id);
const SPLIT_ITEM = "cyborg-monitor-split";
const MAX_ITEM = "cyborg-monitor-maximised";
const TAB_ITEM = "cyborg-monitor-tab";
const NARROW = "(max-width: 700px)";
const MIN_SHARE = 0.1;
const EMPTY_MAP_PX = 200;
const KEY_STEP = 0.05;

export class Layout {
  constructor({ onMapShown }) {
    this.main = document.querySelector("main");
    this.tree = $("view");
    this.map = $("map-view");
    this.splitter = $("splitter");
    this.onMapShown = onMapShown;
    this.share = clampShare(Number(remembered(SPLIT_ITEM, "0.5")));
    this.maximised = ["tree", "map"].includes(remembered(MAX_ITEM, "")) ? remembered(MAX_ITEM, "") : "";
    this.tab = ["map", "tree", "side"].includes(remembered(TAB_ITEM, "map")) ? remembered(TAB_ITEM, "map") : "map";
    this.mapEmpty = true;
    this.narrow = window.matchMedia(NARROW);
    this.narrow.addEventListener("change", () => this.apply());
    this.dragSplitter();
    const menu = $("toolbar-menu");
    menu.addEventListener("click", () => {
      const open = menu.getAttribute("aria-expanded") !== "true";
      menu.setAttribute("aria-expanded", String(open));
      $("toolbar").classList.toggle("open", open);
    });
    for (const button of document.querySelectorAll("button[data-max]")) {
      button.addEventListener("click", () => this.maximise(this.maximised === button.dataset.max ? "" : button.dataset.max));
    }
    for (const button of document.querySelectorAll("#tabs button[data-tab]")) {
      button.addEventListener("click", () => this.showTab(button.dataset.tab));
    }
    this.apply();
  }

  get mapShown() {
    return this.narrow.matches ? this.tab === "map" : this.shownMaximised !== "tree";
  }

  // The panel maximised on the page: none for a map maximised while there is no map to show.
  get shownMaximised() {
    return this.maximised === "map" && this.mapEmpty ? "" : this.maximised;
  }

  maximise(which) {
    this.maximised = which;
    remember(MAX_ITEM, which);
    this.apply();
  }

  showTab(tab) {
    this.tab = tab;
    remember(TAB_ITEM, tab);
    this.apply();
  }

  // Whether the map panel has no map to show (then it takes little room).
  setMapEmpty(empty) {
    if (empty === this.mapEmpty) return;
    this.mapEmpty = empty;
    this.apply();
  }

  setShare(share) {
    this.share = clampShare(share);
    this.apply();
  }

  apply() {
    document.body.classList.toggle("narrow", this.narrow.matches);
    const maximised = this.shownMaximised;
    this.main.dataset.max = maximised;
    this.main.dataset.tab = this.tab;
    // flex-grow in proportion, from a basis of 0: the two panels split what the details leave
    // (grows summing to 1, so they share all of it); a maximised panel grows alone
    const empty = this.mapEmpty && !maximised;
    this.tree.style.flex = empty || maximised ? "1 1 0px" : `${this.share} 1 0px`;
    this.map.style.flex = empty ? `0 0 ${EMPTY_MAP_PX}px` : maximised ? "1 1 0px" : `${1 - this.share} 1 0px`;
    this.splitter.hidden = empty;
    this.splitter.setAttribute("aria-valuenow", String(Math.round(this.share * 100)));
    for (const button of document.querySelectorAll("button[data-max]")) {
      const on = maximised === button.dataset.max;
      button.textContent = on ? "⤡" : "⤢";
      button.title = on ? "Restore the split view" : `Maximise the ${button.dataset.max === "map" ? "map" : "tree"}`;
      button.setAttribute("aria-pressed", String(on));
    }
    for (const button of document.querySelectorAll("#tabs button[data-tab]")) {
      button.setAttribute("aria-selected", String(button.dataset.tab === this.tab));
    }
    this.onMapShown(this.mapShown);
  }

  dragSplitter() {
    const splitter = this.splitter;
    let drag = null; // {left, width} of the tree and map together, at the start
    splitter.addEventListener("pointerdown", (event) => {
      const left = this.tree.getBoundingClientRect().left;
      const right = this.map.getBoundingClientRect().right;
      drag = { left, width: right - left - splitter.offsetWidth };
      try {
        splitter.setPointerCapture(event.pointerId);
      } catch {
        // a synthetic pointer: drag without capture
      }
      splitter.classList.add("dragging");
      event.preventDefault();
    });
    splitter.addEventListener("pointermove", (event) => {
      if (!drag || drag.width <= 0) return;
      this.setShare((event.clientX - drag.left - splitter.offsetWidth / 2) / drag.width);
    });
    const end = () => {
      if (!drag) return;
      drag = null;
      splitter.classList.remove("dragging");
      remember(SPLIT_ITEM, this.share.toFixed(3));
    };
    splitter.addEventListener("pointerup", end);
    splitter.addEventListener("pointercancel", end);
    splitter.addEventListener("dblclick", () => {
      this.setShare(0.5);
      remember(SPLIT_ITEM, "0.5");
    });
    splitter.addEventListener("keydown", (event) => {
      const step = event.key === "ArrowLeft" ? -KEY_STEP : event.key === "ArrowRight" ? KEY_STEP : 0;
      if (!step) return;
      event.preventDefault();
      this.setShare(this.share + step);
      remember(SPLIT_ITEM, this.share.toFixed(3));
    });
  }
}

function clampShare(share) {
  return Number.isFinite(share) ? Math.min(1 - MIN_SHARE, Math.max(MIN_SHARE, share)) : 0.5;
}

// The page's choices kept in localStorage. It may be refused (private windows, storage full):
// then they last this page.
export function remembered(item, fallback) {
  try {
    return localStorage.getItem(item) ?? fallback;
  } catch {
    return fallback;
  }
}

export function remember(item, value) {
  try {
    localStorage.setItem(item, value);
  } catch {
    // not kept
  }
}
