// The tooltip of a tracked object on the map: hovering a marker (or clicking it, which is how a
// touch screen hovers) shows, beside the pointer, what the tracker knows of it: label, id and
// robot, confidence, speed, when it was last seen and how often. It follows the object's
// newest state (refresh() on every frame) and goes when the pointer leaves it or the object
// goes. Text only (textContent): labels come from the bus.

const HIT_PX = 10; // a marker is hit this far from its centre

export class ObjectTip {
  // `root`: the #map-view element; `canvas`: the map's upper canvas; `find(sx, sy, px)`: the
  // object under a point ({robot, item} or null, see trackedAt).
  constructor(root, canvas, find) {
    this.find = find;
    this.point = null; // the pointer, in canvas px, while it is over the map
    this.box = document.createElement("div");
    this.box.id = "map-object-tip";
    this.box.className = "map-tip";
    this.box.hidden = true;
    this.box.setAttribute("role", "tooltip");
    root.append(this.box);
    const at = (event) => {
      const bounds = canvas.getBoundingClientRect();
      this.point = [event.clientX - bounds.left, event.clientY - bounds.top];
      this.refresh();
    };
    canvas.addEventListener("pointermove", (event) => { if (event.pointerType === "mouse") at(event); });
    canvas.addEventListener("click", at);
    canvas.addEventListener("pointerleave", () => {
      this.point = null;
      this.refresh();
    });
  }

  // Shows what is under the pointer now, or nothing.
  refresh() {
    const found = this.point ? this.find(this.point[0], this.point[1], HIT_PX) : null;
    if (!found) {
      if (!this.box.hidden) this.box.hidden = true;
      return;
    }
    const { robot, item } = found;
    const lines = [
      `${item.label || "object"} #${item.id} · ${robot}`,
      `confidence ${Math.round(item.conf * 100)} %`,
      `speed ${Math.hypot(item.vx, item.vy).toFixed(2)} m/s`,
      `last seen ${item.age.toFixed(1)} s ago${item.seen === null ? "" : `, ${item.seen} times`}`,
    ];
    const text = lines.join("\n");
    if (this.box.textContent !== text) this.box.textContent = text;
    this.box.style.left = `${Math.round(this.point[0] + 14)}px`;
    this.box.style.top = `${Math.round(this.point[1] + 14)}px`;
    this.box.hidden = false;
  }

  // The tooltip's text while it is shown, else null (for tests).
  text() {
    return this.box.hidden ? null : this.box.textContent;
  }
}
