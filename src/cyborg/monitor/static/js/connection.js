// The page's WebSocket to the monitor: connects, says hello, reconnects when the link drops.
//
// The hello carries the control seat's secret when this tab held the seat (the monitor sends
// it to the holder only; it is kept for this tab), so a reload or a reconnect keeps control.
//
// `connection.send(command)` returns a promise of the `result` message answering it (commands
// carry a request number `req`). Every other message goes to `onMessage`. `onState` hears
// "open" and "closed" so the page can say when it is offline. A message that is not JSON text
// goes to `onUnreadable(data, error)`.

const RETRY_FIRST_MS = 300;
const RETRY_MAX_MS = 5000;
const SEAT_ITEM = "cyborg-monitor-seat";

export class Connection {
  constructor({ onMessage, onState, onOpen, onUnreadable }) {
    this.onMessage = onMessage;
    this.onUnreadable = onUnreadable;
    this.onState = onState;
    this.onOpen = onOpen;
    this.pending = new Map();
    this.nextReq = 1;
    this.retryMs = RETRY_FIRST_MS;
    this.socket = null;
    this.token = pageToken();
  }

  url() {
    const scheme = location.protocol === "https:" ? "wss:" : "ws:";
    const query = this.token ? `?token=${encodeURIComponent(this.token)}` : "";
    return `${scheme}//${location.host}/ws${query}`;
  }

  // The first connection is the one index.html opened while the modules loaded (it watches
  // the default tree from the start); later ones are made here.
  open() {
    const early = window.__early;
    window.__early = null;
    const socket = early && early.socket.readyState <= WebSocket.OPEN ? early.socket : new WebSocket(this.url());
    this.socket = socket;
    const opened = () => {
      this.retryMs = RETRY_FIRST_MS;
      this.post({ t: "hello", seat: sessionStorage.getItem(SEAT_ITEM) || "" });
      this.onState("open");
      if (socket !== early?.socket) this.onOpen();
    };
    socket.onopen = opened;
    socket.onmessage = (event) => {
      let message;
      try {
        message = JSON.parse(event.data);
      } catch (error) {
        this.onUnreadable(event.data, error); // not JSON text: reported, not thrown
        return;
      }
      if (message.t === "result" && this.pending.has(message.req)) {
        this.pending.get(message.req)(message);
        this.pending.delete(message.req);
        return;
      }
      this.onMessage(message);
    };
    if (socket === early?.socket) {
      for (const event of early.buffered) socket.onmessage(event);
      if (socket.readyState === WebSocket.OPEN) opened();
    }
    socket.onclose = () => {
      if (this.socket !== socket) return;
      this.socket = null;
      for (const resolve of this.pending.values()) {
        resolve({ t: "result", ok: false, message: "the connection dropped" });
      }
      this.pending.clear();
      this.onState("closed");
      setTimeout(() => this.open(), this.retryMs);
      this.retryMs = Math.min(this.retryMs * 2, RETRY_MAX_MS);
    };
  }

  get connected() {
    return this.socket !== null && this.socket.readyState === WebSocket.OPEN;
  }

  // Send without waiting for an answer.
  post(command) {
    if (this.connected) this.socket.send(JSON.stringify(command));
  }

  // Send and wait for the `result` that answers it.
  send(command) {
    if (!this.connected) {
      return Promise.resolve({ ok: false, message: "not connected to the monitor" });
    }
    const req = this.nextReq++;
    return new Promise((resolve) => {
      this.pending.set(req, resolve);
      this.socket.send(JSON.stringify({ ...command, req }));
    });
  }
}

// The control seat's secret, from a seat message that says this page holds the seat.
export function keepSeatSecret(secret) {
  sessionStorage.setItem(SEAT_ITEM, secret);
}

// The control token, from `?token=` in the page's address (kept for this tab). It is then
// taken out of the address bar, so it stays out of the browser's history and off screen.
function pageToken() {
  const params = new URLSearchParams(location.search);
  const fromUrl = params.get("token");
  if (fromUrl) {
    sessionStorage.setItem("cyborg-monitor-token", fromUrl);
    params.delete("token");
    const query = params.toString();
    history.replaceState(history.state, "", `${location.pathname}${query ? `?${query}` : ""}${location.hash}`);
  }
  return fromUrl || sessionStorage.getItem("cyborg-monitor-token") || "";
}
