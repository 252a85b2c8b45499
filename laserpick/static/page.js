// laserpick's operator page: the control panel beside the embedded 3D view.
//
// Plain JavaScript, no build step, no libraries (the robot's computer may have no network).
// Everything goes through the public API, like any other client (see /docs and
// laserpick/client.py): commands are REST calls with the control lease's token; the state
// arrives on the events websocket at 30 Hz, and the page heartbeats on that socket while it
// holds the lease (the server halts motion after 0.5 s of silence).
//
// Inputs, all calling the same few functions (nudge, setDrive, command, stopNow):
//   mouse/touch, keyboard (Tab, Space/Enter, arrows, Esc), switch scanning (one or two
//   switches, as keys), and a gamepad (polled only while one is connected).
//
// This module wires the page at start. The ES modules in page/ hold one concept each:
//   shared.js         what several modules read and write: the lease token, the newest frame
//   settings.js       the user's settings and their storage
//   settings-form.js  the Settings form
//   announce.js       speech and the assertive alerts
//   latency.js        the round trip and the frame age, in the bar
//   api.js, dom.js    the API's address and its refusals; the page's elements by id
//   lease.js          the control lease, and the REST commands sent under it
//   estop.js          STOP, which needs no lease
//   socket.js         the events websocket, its reconnect, and the heartbeat
//   render.js         rendering the state frame
//   nudge.js          aiming the laser: nudges, coalesced
//   actions.js        the panel's buttons: Detect, stepping through grasps, Go, Cancel...
//   drive.js          driving: every input's wish, the dead-man resend, the on-screen pad
//   keyboard.js       the keys, heard in the capture phase
//   switch-keys.js    naming and changing the switches' keys
//   scanning.js       switch scanning
//   gamepad.js        the gamepad
//   view-frame.js     the embedded 3D view
import { ACTIONS } from "./page/actions.js";
import { alertText } from "./page/announce.js";
import { $ } from "./page/dom.js";
import { stopDrivingOnBlur, wireDrivePad } from "./page/drive.js";
import { connectedPads, startPad, watchPads } from "./page/gamepad.js";
import { listenToKeys } from "./page/keyboard.js";
import { watchLatency } from "./page/latency.js";
import { command, giveBackLease } from "./page/lease.js";
import { nudge } from "./page/nudge.js";
import { setAvailable } from "./page/render.js";
import { exitGroup, nameOf } from "./page/scanning.js";
import { settings } from "./page/settings.js";
import { showSettings, wireSettingsForm } from "./page/settings-form.js";
import { shared } from "./page/shared.js";
import { connect, keepBeating } from "./page/socket.js";
import { findView, forgetViewLease, keepViewLease, stopFromView } from "./page/view-frame.js";

function wire() {
  // An unavailable control explains itself instead of acting (capture: before any handler).
  document.addEventListener("click", (e) => {
    const el = e.target.closest("button");
    if (el && el.getAttribute("aria-disabled") === "true") {
      e.preventDefault();
      e.stopImmediatePropagation();
      const latest = shared.latest;
      alertText(`${nameOf(el)} is not available now (${latest ? latest.state.replaceAll("_", " ") : "not connected"}).`);
    }
  }, true);
  for (const [id, fn] of Object.entries(ACTIONS)) $(id).addEventListener("click", () => fn());
  for (const b of document.querySelectorAll("[data-nudge]")) {
    const [sy, sp] = b.dataset.nudge.split(",").map(Number);
    b.addEventListener("click", () => nudge(sy * +settings.step, sp * +settings.step));
  }
  wireDrivePad();
  for (const el of document.querySelectorAll("[data-mode]")) {
    el.addEventListener("change", async () => {
      if (el.getAttribute("aria-disabled") === "true" || !(await command("/mode", { [el.dataset.mode]: el.value }))) {
        if (shared.latest) el.value = shared.latest[el.dataset.mode];  // refused: show what holds
      }
    });
  }
  wireSettingsForm();
  // Take control is the lease form's submit button (Enter in the password field submits).
  $("lease").addEventListener("submit", (e) => e.preventDefault());
  for (const b of document.querySelectorAll(".scan-back")) b.addEventListener("click", exitGroup);
  // Until the first state frame, only STOP is available.
  for (const el of document.querySelectorAll("button:not(#stop):not(#take):not(.keybind):not(.scan-back), [data-mode]")) {
    setAvailable(el, false);
  }
  if (connectedPads().length) startPad();
}

// At start, in this order: the timers and the window's listeners, then the controls, the
// settings, the 3D view and the events websocket.
watchLatency();
keepBeating();
addEventListener("pagehide", () => {
  giveBackLease();
  forgetViewLease();
});
stopDrivingOnBlur();
listenToKeys();
watchPads();
keepViewLease();
stopFromView();
// Keep focused controls clear of the sticky bar, whatever its height (WCAG 2.4.11).
new ResizeObserver(() => {
  document.documentElement.style.setProperty("--bar-h", `${document.querySelector(".bar").offsetHeight}px`);
}).observe(document.querySelector(".bar"));

wire();
showSettings();
findView();
connect();
