// The latency figures in the bar (ms): the round trip of the last command (or of a probe),
// and the age of the newest state frames.
import { API } from "./api.js";
import { $ } from "./dom.js";
import { shared } from "./shared.js";

let lastCommandAt = 0;
const frameAges = [];  // ms, the last second of frames

export function noteRtt(ms, isCommand) {
  if (isCommand) lastCommandAt = performance.now();
  showMs($("rtt"), ms);
}
export function noteFrame(frame) {
  frameAges.push(Date.now() - frame.t * 1000);
}
function showMs(el, ms) {
  el.textContent = `${Math.round(ms)} ms`;
  el.className = ms > 250 ? "slow" : ms > 100 ? "fair" : "";
}

export function watchLatency() {
  // Frame age = now - the frame's server time: right on one machine; across machines it also
  // holds their clock offset. Shown as the mean of the last second, four times a second.
  setInterval(() => {
    const latest = shared.latest;
    if (!latest) return;
    const stale = Date.now() - latest.t * 1000;
    const ms = frameAges.length && stale < 1000
      ? frameAges.reduce((a, b) => a + b, 0) / frameAges.length : stale;
    showMs($("age"), ms);
    frameAges.length = 0;
  }, 250);
  // With no command for a while, probe the round trip with a cheap read.
  setInterval(async () => {
    if (document.hidden || performance.now() - lastCommandAt < 3000) return;
    const t0 = performance.now();
    try { await fetch(`${API}/health`, { cache: "no-store" }); noteRtt(performance.now() - t0, false); }
    catch { /* the socket's state says we are disconnected */ }
  }, 3000);
}
