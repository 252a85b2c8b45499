// The events websocket: state frames in at 30 Hz, reconnecting after a loss (0.5 s, doubling
// to 5 s); and the heartbeat on it every 150 ms while the page holds the lease (the server
// halts motion after its watchdog time of silence, 0.5 s).
import { alertText } from "./announce.js";
import { API } from "./api.js";
import { noteFrame } from "./latency.js";
import { renderLease, renderOffline, scheduleRender } from "./render.js";
import { shared } from "./shared.js";

let ws = null;
let reconnectMs = 500;

export function connect() {
  const url = new URL(`${API}/events`, location.href);
  url.protocol = location.protocol === "https:" ? "wss:" : "ws:";
  ws = new WebSocket(url);
  ws.onopen = () => { reconnectMs = 500; heartbeat(); };
  ws.onmessage = (e) => {
    let m;
    try { m = JSON.parse(e.data); } catch { return; }
    if (m.type === "hello") {
      watchdogMs = 1000 * (m.watchdog_s || 0.5);
    } else if (m.type === "state") {
      shared.latest = m;
      noteFrame(m);
      scheduleRender();
    } else if (m.type === "event" && m.name === "watchdog") {
      alertText(m.message);
    } else if (m.type === "error" && /heartbeat/.test(m.detail || "")) {
      shared.token = null;  // someone took over; the next command takes control again
      renderLease();
    }
  };
  ws.onclose = () => {
    ws = null;
    renderOffline();
    setTimeout(connect, reconnectMs);
    reconnectMs = Math.min(reconnectMs * 2, 5000);
  };
}

let watchdogMs = 500;  // from the server's hello
let lastBeat = 0;
let lateWarnedAt = -Infinity;
export function heartbeat() {
  const token = shared.token;
  if (!(token && ws && ws.readyState === WebSocket.OPEN)) { lastBeat = 0; return; }
  // The robot halts when its controller is silent for the watchdog time. Say so when this
  // browser falls behind (a starved CPU: software WebGL, say), before the robot halts.
  const now = performance.now();
  if (lastBeat && now - lastBeat > 0.7 * watchdogMs && now - lateWarnedAt > 30000) {
    lateWarnedAt = now;
    alertText(`This browser is falling behind (a heartbeat ${Math.round(now - lastBeat)} ms late; `
      + `the robot halts after ${watchdogMs} ms of silence). Hiding the 3D view (Settings) frees the computer.`);
  }
  lastBeat = now;
  ws.send(JSON.stringify({ type: "heartbeat", token }));
}

export function keepBeating() {
  setInterval(heartbeat, 150);
}
