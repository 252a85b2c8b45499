// laserpick's operator page: the control panel beside the embedded 3D view.
//
// Plain JavaScript, no build step, no libraries (the robot's computer may have no network).
// Everything goes through the public API, like any other client (see /docs and
// laserpick/client.py): commands are REST calls with the control lease's token; the state
// arrives on the events websocket at 30 Hz, and the page heartbeats on that socket while it
// holds the lease (the server halts motion after 0.5 s of silence).
//
// Inputs, all calling the same few functions (nudge, drive, command, stopNow):
//   mouse/touch, keyboard (Tab, Space/Enter, arrows, Esc), switch scanning (one or two
//   switches, as keys), and a gamepad (polled only while one is connected).
"use strict";

// Relative, so the page works at / and behind a proxy under a prefix.
const API = "api/v1";
const $ = (id) => document.getElementById(id);

// Robot states in which the laser may be aimed (the server's AIMABLE).
const AIMABLE = new Set(["idle", "aiming", "perceived", "grasps_ready", "holding", "awaiting_place"]);
const FINE_STEP = 0.01;   // rad: Shift+arrow
const DRIVE_PERIOD = 250; // ms: a drive command is a 0.5 s dead-man, so resend at 4 Hz
const PAD_RATE = 0.5;     // rad/s: the laser's turn rate at full stick
const PAD_DEAD = 0.2;     // stick dead zone (of full travel)
const PAD_DEADMAN = 5;    // RB, standard mapping: hold for any drive motion
// rad: the server's largest nudge per command, from GET /health; null until the server says
// (a server that does not say is not second-guessed here).
let maxNudge = null;

// --- settings, remembered per user in this browser (localStorage) -------------------------

const DEFAULTS = {
  step: "0.05", level: "cluster", speed: "0.3", speech: false, showView: true, viewDetail: "auto",
  scanMode: "off", period: 1.0, cycles: 3, accept: 0.1, release: 0.1,  // as the switch adapter
  key1: "Space", key2: "Enter",
};
let user = safeGet("laserpick.user") || "operator";
let settings = loadSettings(user);

function safeGet(key) {
  try { return localStorage.getItem(key); } catch { return null; }  // storage may be blocked
}
function loadSettings(name) {
  try { return { ...DEFAULTS, ...JSON.parse(safeGet(`laserpick.settings.${name}`) || "{}") }; }
  catch { return { ...DEFAULTS }; }
}
function saveSettings() {
  try {
    localStorage.setItem("laserpick.user", user);
    localStorage.setItem(`laserpick.settings.${user}`, JSON.stringify(settings));
  } catch { /* not remembered, but still applied */ }
}

// Put the settings into the form, and apply their side effects.
function showSettings() {
  $("user").value = user;
  for (const el of document.querySelectorAll("[data-setting]")) {
    const v = settings[el.dataset.setting];
    if (el.type === "checkbox") el.checked = Boolean(v);
    else el.value = String(v);
  }
  for (const k of ["key1", "key2"]) $(k).textContent = `Switch ${k.slice(-1)} key: ${keyName(settings[k])}`;
  showView(settings.showView);
  setScanMode(settings.scanMode);
}

function readSetting(el) {
  const k = el.dataset.setting;
  if (el.type === "checkbox") settings[k] = el.checked;
  else if (el.type === "number") {
    const v = parseFloat(el.value);
    // Out of range or not a number: keep the old value and show it again.
    if (Number.isFinite(v)) settings[k] = Math.min(+el.max, Math.max(+el.min, v));
    el.value = String(settings[k]);
  } else settings[k] = el.value;
  saveSettings();
  if (k === "showView" || k === "viewDetail") showView(settings.showView);
  if (k === "scanMode") setScanMode(settings.scanMode);
  if (k === "speech" && settings.speech) speak("Speech on.", true);
}

// --- speech (optional, off by default) ----------------------------------------------------

const canSpeak = "speechSynthesis" in window && typeof SpeechSynthesisUtterance === "function";
function speak(text, interrupt) {
  if (!settings.speech || !canSpeak || !text) return;
  if (interrupt) speechSynthesis.cancel();  // the newest news, not a backlog
  speechSynthesis.speak(new SpeechSynthesisUtterance(text));
}

// --- messages: polite status, assertive alerts --------------------------------------------

let lastAlert = { text: "", at: 0, timer: null };
function alertText(text) {
  // The same alert again within 2 s (a held key's refusals) is said once.
  if (text === lastAlert.text && performance.now() - lastAlert.at < 2000) return;
  lastAlert = { text, at: performance.now(), timer: lastAlert.timer };
  // Empty the region first, so that the same text later is announced again.
  clearAlert();
  lastAlert.timer = setTimeout(() => { $("alert").textContent = text; }, 30);
  speak(text, true);
}
function clearAlert() {
  clearTimeout(lastAlert.timer);
  $("alert").textContent = "";
}

// A refusal's detail as one readable line (a 422 lists its fields), as client.describe().
function describe(detail) {
  if (Array.isArray(detail)) {
    return detail.map((e) => {
      const loc = (e.loc || []).filter((p) => p !== "body").join(".");
      return loc ? `${loc}: ${e.msg}` : String(e.msg);
    }).join("; ");
  }
  return typeof detail === "string" ? detail : JSON.stringify(detail);
}
function refusal(status, body) {
  const why = describe(body.detail ?? body);
  if (status === 409) return `Refused while ${body.state || "busy"}: ${why}`;
  if (status === 422) return `Invalid input: ${why}`;
  if (status === 401) return `Not in control: ${why}`;
  return `Error ${status}: ${why}`;
}

// --- latency ------------------------------------------------------------------------------

let lastCommandAt = 0;
const frameAges = [];  // ms, the last second of frames
function noteRtt(ms, isCommand) {
  if (isCommand) lastCommandAt = performance.now();
  showMs($("rtt"), ms);
}
function showMs(el, ms) {
  el.textContent = `${Math.round(ms)} ms`;
  el.className = ms > 250 ? "slow" : ms > 100 ? "fair" : "";
}
// Frame age = now - the frame's server time: right on one machine; across machines it also
// holds their clock offset. Shown as the mean of the last second, four times a second.
setInterval(() => {
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

// --- the lease and commands ---------------------------------------------------------------

let token = null;
let taking = null;  // the request for the lease in flight: commands sent meanwhile share it
const holderName = () => `${user} (browser page)`.slice(0, 64);

function takeControl() {
  if (!taking) taking = requestLease().finally(() => { taking = null; });
  return taking;
}
async function requestLease() {
  const body = { name: holderName(), source: "console" };
  const pw = $("password").value;
  if (pw) body.password = pw;
  const t0 = performance.now();
  let r;
  try {
    r = await fetch(`${API}/control`, {
      method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body),
    });
  } catch {
    alertText("Cannot reach the robot's server.");
    return false;
  }
  noteRtt(performance.now() - t0, true);
  const data = await r.json().catch(() => ({}));
  if (r.ok) {
    token = data.token;
    heartbeat();
    renderLease();
    return true;
  }
  token = null;
  if (r.status === 401) {
    $("password-field").hidden = false;
    alertText("This robot needs the operator password: type it, then Take control.");
  } else if (r.status === 409) {
    alertText(`Cannot take control: ${describe(data.detail)}`);
  } else {
    alertText(refusal(r.status, data));
  }
  renderLease();
  return false;
}

// Send a command; its JSON answer, or null when refused (the refusal is announced). Takes
// the lease first when the page has none, and once more when the server says the token no
// longer holds it (it lapsed, or the 3D view of this station took it over).
async function command(path, body, method = "POST", retried = false) {
  if (!token && !(await takeControl())) return null;
  const headers = { Authorization: `Bearer ${token}` };
  if (body !== undefined) headers["Content-Type"] = "application/json";
  const t0 = performance.now();
  let r;
  try {
    r = await fetch(API + path, {
      method, headers, body: body === undefined ? undefined : JSON.stringify(body),
    });
  } catch {
    alertText("The robot's server did not answer.");
    return null;
  }
  noteRtt(performance.now() - t0, true);
  if (r.status === 401 && !retried) {
    token = null;
    return command(path, body, method, true);
  }
  const data = await r.json().catch(() => ({}));
  if (!r.ok) {
    alertText(refusal(r.status, data));
    return null;
  }
  clearAlert();  // the operator acted and was heard: an older refusal no longer applies
  return data;
}

// The e-stop needs no token: anyone watching may stop the robot.
async function stopNow() {
  stopDriving(false);
  pending.dyaw = pending.dpitch = 0;
  const headers = token ? { Authorization: `Bearer ${token}` } : {};
  const t0 = performance.now();
  try {
    const r = await fetch(`${API}/stop`, { method: "POST", headers });
    noteRtt(performance.now() - t0, true);
    alertText(r.ok ? "STOP: motion halted." : `STOP failed: error ${r.status}.`);
  } catch {
    alertText("STOP could not reach the server!");
  }
}

// --- the events websocket -----------------------------------------------------------------

let ws = null;
let latest = null;          // the newest state frame
let reconnectMs = 500;

function connect() {
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
      latest = m;
      frameAges.push(Date.now() - m.t * 1000);
      scheduleRender();
    } else if (m.type === "event" && m.name === "watchdog") {
      alertText(m.message);
    } else if (m.type === "error" && /heartbeat/.test(m.detail || "")) {
      token = null;  // someone took over; the next command takes control again
      renderLease();
    }
  };
  ws.onclose = () => {
    ws = null;
    $("state-badge").textContent = "offline";
    $("status").textContent = seen.status = "Not connected to the robot. Retrying…";
    setTimeout(connect, reconnectMs);
    reconnectMs = Math.min(reconnectMs * 2, 5000);
  };
}

let watchdogMs = 500;  // from the server's hello
let lastBeat = 0;
let lateWarnedAt = -Infinity;
function heartbeat() {
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
setInterval(heartbeat, 150);

// Give the lease back when the page goes away (keepalive: the request outlives the page).
addEventListener("pagehide", () => {
  if (token) {
    fetch(`${API}/control`, {
      method: "DELETE", headers: { Authorization: `Bearer ${token}` }, keepalive: true,
    }).catch(() => {});
  }
  if (viewUrl && viewToken) leaseCookie("");
});

// --- rendering the state (at most 10 times a second, touching only what changed) ----------

let renderTimer = null;
function scheduleRender() {
  if (!renderTimer) renderTimer = setTimeout(() => { renderTimer = null; render(); }, 100);
}

const seen = { status: "", failure: "", estopped: false, driveStop: "", projector: "" };
let projectorN = 0;

function statusText(s) {
  const parts = [];
  if (s.estopped && !s.message.includes("E-STOP")) parts.push("E-STOP latched");
  if (s.drive_stop) parts.push(s.drive_stop);
  const d = s.grasps && s.grasps.describe;
  if (d && !s.message.includes(d)) parts.push(d);
  parts.push(s.message);
  return parts.join(", ");
}

function render() {
  const s = latest;
  if (!s) return;
  const badge = $("state-badge");
  badge.textContent = s.estopped ? "E-STOP" : s.busy ? `${s.state}: ${s.job}` : s.state.replaceAll("_", " ");
  badge.className = "badge" + (s.estopped ? " estop" : s.failure ? " failed" : "");

  const text = statusText(s);
  if (text !== seen.status) {
    seen.status = text;
    $("status").textContent = text;
    speak(text, false);
  }
  const failure = s.failure ? `Failed (${s.failure.kind.replaceAll("_", " ")}): ${s.failure.message}` : "";
  if (failure && failure !== seen.failure) alertText(failure);
  seen.failure = failure;
  if (s.estopped && !seen.estopped) alertText("E-STOP latched: motion is halted until Reset stop.");
  seen.estopped = s.estopped;
  if (s.drive_stop && s.drive_stop !== seen.driveStop) alertText(s.drive_stop);
  seen.driveStop = s.drive_stop || "";

  renderAvailability(s);
  renderLease();
  renderGrasp(s);
  for (const el of document.querySelectorAll("[data-mode]")) {
    // Follow the robot, except while the operator is choosing.
    if (document.activeElement !== el && el.value !== s[el.dataset.mode]) el.value = s[el.dataset.mode];
  }
  // The projector image changes with the task, not with every frame.
  const key = [s.state, s.mark, s.place_mark, s.target && s.target.points].join("|");
  if (key !== seen.projector) {
    seen.projector = key;
    $("projector").src = `${API}/projector.png?v=${++projectorN}`;
    $("projector").alt = s.target ? "Projector image: the target is lit (white)."
      : s.place_mark ? "Projector image: the place spot is lit." : "Projector image: nothing is lit.";
  }
}

function renderAvailability(s) {
  const st = s.state, busy = s.busy;
  const aim = !busy && AIMABLE.has(st);
  const grasps = !busy && st === "grasps_ready";
  const can = {
    detect: !busy && ((["aiming", "awaiting_place"].includes(st) && s.laser.on)
      || ["perceived", "grasps_ready"].includes(st)),
    "laser-off": aim && s.laser.on,
    prev: grasps, next: grasps, auto: grasps,
    go: !busy && !s.estopped && (st === "grasps_ready" || st === "holding"),
    cancel: busy || ["aiming", "perceived", "grasps_ready", "awaiting_place"].includes(st),
    "reset-stop": s.estopped,
  };
  for (const [id, ok] of Object.entries(can)) setAvailable($(id), ok);
  for (const b of document.querySelectorAll("[data-nudge]")) setAvailable(b, aim);
  for (const b of document.querySelectorAll("[data-drive]")) setAvailable(b, aim && !s.estopped);
  for (const el of document.querySelectorAll("[data-mode]")) setAvailable(el, !busy);
  const label = st === "awaiting_place" ? "Detect place" : "Detect";
  if ($("detect").textContent !== label) $("detect").textContent = label;
}

// aria-disabled, not disabled: a control that becomes unavailable keeps the focus.
function setAvailable(el, ok) {
  const v = ok ? "false" : "true";
  if (el.getAttribute("aria-disabled") !== v) el.setAttribute("aria-disabled", v);
}

function renderLease() {
  const l = latest && latest.lease;
  const mine = token && l && l.held && l.source === "console" && l.holder === holderName();
  let text = "Nobody has control.";
  if (mine || (token && !l)) text = "You have control.";
  else if (l && l.held) text = `Controlled by ${l.holder} (${l.source}).`;
  if ($("lease-text").textContent !== text) $("lease-text").textContent = text;
  $("take").hidden = Boolean(mine);
}

function renderGrasp(s) {
  let text = s.target ? `Target: ${s.target.points} points lit. No grasps yet.` : "No target yet.";
  if (s.grasps && s.current) {
    // Why this grasp: its score and the factors of 004's objective (eq. 3-7).
    const c = s.current;
    const f = c.factors
      ? " (" + Object.entries(c.factors).map(([k, v]) => `${k} ${v.toFixed(2)}`).join(", ") + ")" : "";
    // A grasp whose pads meet the object toward their edge is offered after the others.
    const edge = c.pads_centred === false ? " Its pads meet the object toward their edge." : "";
    const go = s.selection === "manual" ? "Go picks this grasp." : "Go picks the best grasp that plans.";
    text = `Grasp: ${s.grasps.describe}. Score ${c.score.toFixed(2)}${f}.${edge} Opening ${Math.round(c.width * 1000)} mm. ${go}`;
  }
  if ($("grasp-info").textContent !== text) $("grasp-info").textContent = text;
}

// --- the actions --------------------------------------------------------------------------

// Laser nudges are coalesced: keys repeat at 30 Hz and a stick moves continuously, but only
// one nudge is in flight at a time, carrying the sum of what came meanwhile.
const pending = { dyaw: 0, dpitch: 0, busy: false };
function nudge(dyaw, dpitch) {
  pending.dyaw += dyaw;
  pending.dpitch += dpitch;
  flushNudge();
}
async function flushNudge() {
  if (pending.busy || (Math.abs(pending.dyaw) < 1e-4 && Math.abs(pending.dpitch) < 1e-4)) return;
  const clamp = (v) => (maxNudge === null ? v : Math.max(-maxNudge, Math.min(maxNudge, v)));
  const dyaw = clamp(pending.dyaw), dpitch = clamp(pending.dpitch);
  pending.dyaw -= dyaw;
  pending.dpitch -= dpitch;
  pending.busy = true;
  const ok = await command("/laser/nudge", { dyaw, dpitch });
  pending.busy = false;
  if (!ok) pending.dyaw = pending.dpitch = 0;  // refused: do not replay it later
  else flushNudge();
}

// Detect: light both beams (confirm), or, once the target is perceived, find grasps again.
function detect() {
  const st = latest && latest.state;
  if (st === "perceived" || st === "grasps_ready") return command("/detect");
  return command("/laser/confirm");
}
// The gamepad's A: whatever moves the task on.
function primary() {
  const st = latest && latest.state;
  if (st === "grasps_ready" || st === "holding") return command("/execute");
  return detect();
}

// Stepping to another grasp makes the choice manual first, so that Go picks the grasp shown
// (as the switch and joystick adapters do); Auto goes back to the system's choice.
async function stepGrasp(dir) {
  if (latest && latest.selection === "auto" && !(await command("/mode", { selection: "manual" }))) return;
  await command(`/grasps/${dir}`, { level: settings.level });
}
async function autoGrasp() {
  if ((await command("/grasps/auto")) && latest && latest.selection !== "auto") {
    await command("/mode", { selection: "auto" });
  }
}

const ACTIONS = {
  detect,
  "laser-off": () => command("/laser", undefined, "DELETE"),
  prev: () => stepGrasp("prev"),
  next: () => stepGrasp("next"),
  auto: autoGrasp,
  go: () => command("/execute"),
  cancel: () => { stopDriving(true); return command("/cancel"); },
  "reset-stop": () => command("/stop/reset"),
  stop: stopNow,
  take: takeControl,
};

// --- driving: hold to drive, click for one step -------------------------------------------

// Each input (pointer, keys, gamepad) holds a [forward, turn] wish in -1..1; the sum drives.
const driveWish = new Map();
let driveTimer = null;
let lastSent = "0,0";

function driveSpeeds() {
  let f = 0, t = 0;
  for (const [a, b] of driveWish.values()) { f += a; t += b; }
  f = Math.max(-1, Math.min(1, f));
  t = Math.max(-1, Math.min(1, t));
  const v = +settings.speed;
  return [f * v, t * Math.min(1, 2 * v)];  // turn: rad/s, twice the speed in m/s
}
// Drive commands are numbered: fetches on separate connections can reach the server out of
// order, and the server drops a drive older than one it applied, so the stop sent on release
// is never overtaken by the drive sent just before it.
let driveSeq = 0;
function sendDrive(v, w, duration = 0.5) {
  return command("/drive", { v: +v.toFixed(3), w: +w.toFixed(3), duration, seq: ++driveSeq });
}
// source: "pointer", "keys" or "pad"; wish: [f, t] or null to let go. coast: a short press
// (a click) lets its 0.5 s step run out instead of stopping at once.
function setDrive(source, wish, coast = false) {
  if (wish) driveWish.set(source, wish); else driveWish.delete(source);
  const [v, w] = driveSpeeds();
  const key = `${v.toFixed(2)},${w.toFixed(2)}`;
  if (v === 0 && w === 0) {
    if (driveTimer) {
      clearInterval(driveTimer);
      driveTimer = null;
      if (!coast) sendDrive(0, 0, 0.1);
    }
    lastSent = key;
    return;
  }
  if (key !== lastSent) sendDrive(v, w);  // a new direction: at once, not at the next tick
  lastSent = key;
  if (!driveTimer) {
    driveTimer = setInterval(() => { const [a, b] = driveSpeeds(); sendDrive(a, b); }, DRIVE_PERIOD);
  }
}
function stopDriving(send) {
  driveWish.clear();
  for (const b of document.querySelectorAll(".held")) b.classList.remove("held");
  if (driveTimer) {
    clearInterval(driveTimer);
    driveTimer = null;
    if (send) sendDrive(0, 0, 0.1);
  }
  lastSent = "0,0";
}
addEventListener("blur", () => { driveKeys.clear(); if (driveWish.size) stopDriving(true); });

function wireDrivePad() {
  for (const b of document.querySelectorAll("[data-drive]")) {
    const wish = b.dataset.drive.split(",").map(Number);
    let downAt = 0;
    let fromPointer = false;
    b.addEventListener("pointerdown", (e) => {
      if (b.getAttribute("aria-disabled") === "true" || e.button !== 0) return;
      fromPointer = true;
      downAt = performance.now();
      b.setPointerCapture(e.pointerId);
      b.classList.add("held");
      setDrive("pointer", wish);
    });
    const release = () => {
      if (!b.classList.contains("held")) return;
      b.classList.remove("held");
      setDrive("pointer", null, performance.now() - downAt < 300);
    };
    b.addEventListener("pointerup", release);
    b.addEventListener("pointercancel", release);
    b.addEventListener("lostpointercapture", release);
    // A click that no pointer made (Space, Enter, a switch, a screen reader): one 0.5 s step.
    b.addEventListener("click", () => {
      if (fromPointer) { fromPointer = false; return; }
      const [f, t] = wish;
      const v = +settings.speed;
      sendDrive(f * v, t * Math.min(1, 2 * v));
    });
  }
}

// --- keyboard -----------------------------------------------------------------------------

const ARROWS = { ArrowUp: [0, 1], ArrowDown: [0, -1], ArrowLeft: [1, 0], ArrowRight: [-1, 0] };
const DRIVE_ARROWS = { ArrowUp: [1, 0], ArrowDown: [-1, 0], ArrowLeft: [0, 1], ArrowRight: [0, -1] };
const driveKeys = new Set();
let listeningFor = null;  // "key1" or "key2" while a switch key is being changed

function keyName(code) {
  return code.replace(/^Key/, "").replace(/^Digit/, "").replace(/^Arrow/, "Arrow ");
}
const isTyping = (el) => el && (el.tagName === "TEXTAREA"
  || (el.tagName === "INPUT" && !["checkbox", "radio", "button"].includes(el.type)));
function switchOf(e) {
  if (settings.scanMode === "off" || isTyping(e.target) || listeningFor) return 0;
  if (e.code === settings.key1) return 1;
  if (e.code === settings.key2 && settings.scanMode === "step") return 2;
  return 0;
}
function driveKeyWish() {
  let f = 0, t = 0;
  for (const k of driveKeys) { f += DRIVE_ARROWS[k][0]; t += DRIVE_ARROWS[k][1]; }
  return f || t ? [f, t] : null;
}

// Capture phase on the window: Esc stops whatever has the focus, and the switch keys never
// reach (and press) the focused control.
addEventListener("keydown", (e) => {
  if (e.key === "Escape") {
    e.preventDefault();
    if (listeningFor) endListening();
    stopNow();
    return;
  }
  if (listeningFor) {
    if (e.key === "Tab") { endListening(); return; }  // Tab stays for moving on
    e.preventDefault();
    settings[listeningFor] = e.code;
    saveSettings();
    endListening();
    return;
  }
  const sw = switchOf(e);
  if (sw) {
    e.preventDefault();
    e.stopPropagation();
    if (!e.repeat) switchDown(sw);
    return;
  }
  if (!(e.key in ARROWS) || isTyping(e.target) || e.target.tagName === "SELECT"
      || e.altKey || e.ctrlKey || e.metaKey) return;
  e.preventDefault();
  if ($("arrows-drive").checked || $("g-drive").contains(e.target)) {
    if (!e.repeat) { driveKeys.add(e.key); setDrive("keys", driveKeyWish()); }
  } else if (latest && AIMABLE.has(latest.state) && !latest.busy) {
    const [sy, sp] = ARROWS[e.key];
    const step = e.shiftKey ? FINE_STEP : +settings.step;
    nudge(sy * step, sp * step);
  }
}, true);

addEventListener("keyup", (e) => {
  const sw = switchOf(e);
  if (sw) { e.preventDefault(); e.stopPropagation(); switchUp(); return; }
  if (driveKeys.delete(e.key)) setDrive("keys", driveKeyWish());
}, true);

function endListening() {
  listeningFor = null;
  for (const k of ["key1", "key2"]) {
    $(k).classList.remove("listening");
    $(k).textContent = `Switch ${k.slice(-1)} key: ${keyName(settings[k])}`;
  }
}

// --- switch scanning ----------------------------------------------------------------------
//
// Groups first, then the item within the group. One switch (auto): the highlight moves by
// itself every scan period; the switch selects. Two switches (step): switch 1 moves it,
// switch 2 selects. After an item acts, the highlight stays on it for a whole period, so a
// second press repeats it (nudging the laser is many presses). Unavailable items and groups
// with nothing available are skipped. The highlight is steady (no blinking) and announced.

const scan = {
  on: false, level: "top", group: null, el: null, cycles: 0, timer: null,
  down: false, ignored: false, acceptTimer: null, lastRelease: -Infinity, driveFrom: 0,
};
const TOP = () => ["stop", "reset-stop", "g-laser", "g-grasps", "cancel", "g-drive", "g-mode"].map($);

function usable(el) {
  return el && !el.hidden && el.getClientRects().length > 0 && !el.disabled
    && el.getAttribute("aria-disabled") !== "true" && !el.hasAttribute("data-noscan");
}
const groupItems = (g) => [...g.querySelectorAll("button, select")].filter(usable);
// A group is worth entering while it can act: a page setting (a step size) or its Back
// item alone does not count.
const hasActions = (g) => groupItems(g).some((el) => !el.matches(".scan-back, [data-setting]"));
const isGroup = (el) => el.dataset.scan === "group";
const topEntries = () => TOP().filter((el) => (isGroup(el) ? hasActions(el) : usable(el)));
const entries = () => (scan.level === "top" ? topEntries() : groupItems(scan.group));

function nameOf(el) {
  if (isGroup(el)) return `${el.querySelector("legend").textContent} group`;
  if (el.tagName === "SELECT") {
    const label = el.labels[0] ? el.labels[0].firstChild.textContent.trim() : "";
    return `${label}: ${el.selectedOptions[0].textContent}`;
  }
  const hidden = [...el.querySelectorAll("[aria-hidden='true']")].map((n) => n.textContent);
  return hidden.reduce((t, h) => t.replace(h, ""), el.textContent).trim();
}

function highlight(el) {
  if (scan.el) scan.el.classList.remove("scan-hl");
  scan.el = el;
  if (!el) return;
  el.classList.add("scan-hl");
  el.scrollIntoView({ block: "nearest" });
  const text = nameOf(el);
  $("scan-status").textContent = `Scanning: ${text}`;
  speak(text, true);
}

function schedule() {
  clearTimeout(scan.timer);
  if (settings.scanMode === "auto" && scan.on && !scan.down) {
    scan.timer = setTimeout(() => { advance(); schedule(); }, settings.period * 1000);
  }
}

function startScan() {
  scan.on = true;
  scan.level = "top";
  scan.group = null;
  scan.cycles = 0;
  highlight(topEntries()[0]);
  schedule();
}
function pauseScan() {
  scan.on = false;
  clearTimeout(scan.timer);
  highlight(null);
  $("scan-status").textContent = "Scanning paused: press switch 1 to start again.";
}

function advance() {
  const list = entries();
  if (scan.level === "group" && !hasActions(scan.group)) { exitGroup(); return; }  // nothing left
  if (!list.length) { pauseScan(); return; }
  let i = list.indexOf(scan.el) + 1;
  if (i >= list.length) {
    i = 0;
    scan.cycles += 1;
    if (settings.scanMode === "auto" && settings.cycles > 0 && scan.cycles >= settings.cycles) {
      if (scan.level === "group") exitGroup(); else pauseScan();
      return;
    }
  }
  highlight(list[i]);
}

function enterGroup(g) {
  scan.level = "group";
  scan.group = g;
  scan.cycles = 0;
  highlight(groupItems(g)[0]);
}
function exitGroup() {
  const g = scan.group;
  scan.level = "top";
  scan.group = null;
  scan.cycles = 0;
  highlight(hasActions(g) ? g : topEntries()[0]);
}

// Select the highlighted entry: enter a group, or act and stay on the item.
function select(el) {
  if (!el) return;
  if (isGroup(el)) enterGroup(el);
  else if (el.classList.contains("scan-back")) exitGroup();
  else {
    activate(el);
    scan.cycles = 0;
    highlight(el);
  }
}
function activate(el) {
  if (el.tagName === "SELECT") {  // a select steps to its next option
    el.selectedIndex = (el.selectedIndex + 1) % el.options.length;
    el.dispatchEvent(new Event("change", { bubbles: true }));
  } else if (el.dataset.drive && scan.down) {
    // A drive item is a dead-man: it drives while the switch stays held (a short press:
    // one 0.5 s step).
    scan.driveFrom = performance.now();
    setDrive("switch", el.dataset.drive.split(",").map(Number));
  } else {
    el.click();
  }
}

function switchDown(sw) {
  const now = performance.now();
  // Release time: a press this soon after the last release is a tremor, not a choice.
  if (now - scan.lastRelease < settings.release * 1000) { scan.ignored = true; return; }
  scan.down = true;
  scan.ignored = false;
  clearTimeout(scan.timer);  // the highlight holds still while the switch is down
  const target = scan.el;    // what was highlighted when the press began
  const accept = () => { scan.acceptTimer = null; onSwitch(sw, target); };
  // Acceptance time: the switch must be held this long to count.
  if (settings.accept > 0) scan.acceptTimer = setTimeout(accept, settings.accept * 1000);
  else accept();
}
function switchUp() {
  if (scan.ignored) { scan.ignored = false; return; }
  scan.down = false;
  scan.lastRelease = performance.now();
  if (driveWish.has("switch")) setDrive("switch", null, scan.lastRelease - scan.driveFrom < 300);
  if (scan.acceptTimer) { clearTimeout(scan.acceptTimer); scan.acceptTimer = null; }  // too short
  schedule();
}
function onSwitch(sw, target) {
  if (!scan.on) { startScan(); return; }
  if (settings.scanMode === "auto" || sw === 2) select(target && target.isConnected ? target : scan.el);
  else advance();
}

function setScanMode(mode) {
  const on = mode !== "off";
  for (const b of document.querySelectorAll(".scan-back")) b.hidden = !on;
  $("scan-status").hidden = !on;
  if (!on) { scan.on = false; clearTimeout(scan.timer); highlight(null); return; }
  const k1 = keyName(settings.key1), k2 = keyName(settings.key2);
  pauseScan();
  $("scan-status").textContent = mode === "auto"
    ? `One-switch scanning: press ${k1} to start.`
    : `Two-switch scanning: ${k1} moves, ${k2} selects. Press ${k1} to start.`;
}

// --- gamepad (polled with requestAnimationFrame only while one is connected) --------------

let padPolling = false;
let padPrev = [];
let padT = 0;
let padDriving = false;

const deadZone = (v) => (Math.abs(v) < PAD_DEAD ? 0 : Math.sign(v) * (Math.abs(v) - PAD_DEAD) / (1 - PAD_DEAD));
function connectedPads() {
  return [...(navigator.getGamepads ? navigator.getGamepads() : [])].filter((p) => p && p.connected !== false);
}
function startPad() {
  if (padPolling) return;
  padPolling = true;
  padT = performance.now();
  requestAnimationFrame(pollPad);
}
function pollPad(t) {
  const pad = connectedPads()[0];
  if (!pad) {
    padPolling = false;
    if (padDriving) { padDriving = false; setDrive("pad", null); }
    return;
  }
  const dt = Math.min(0.1, Math.max(0, (t - padT) / 1000));
  padT = t;
  const x = deadZone(pad.axes[0] || 0), y = deadZone(pad.axes[1] || 0);
  const pressed = (i) => Boolean(pad.buttons[i] && pad.buttons[i].pressed);
  if (pressed(PAD_DEADMAN) && (x || y)) {
    padDriving = true;  // the dead-man is held: the stick drives the base
    setDrive("pad", [-y, -x]);
  } else {
    if (padDriving) { padDriving = false; setDrive("pad", null); }
    // Without the dead-man the stick turns the laser, at a rate (stick up: pitch up).
    if ((x || y) && latest && AIMABLE.has(latest.state) && !latest.busy) {
      nudge(-x * PAD_RATE * dt, -y * PAD_RATE * dt);
    }
  }
  const edges = { 0: primary, 1: ACTIONS.cancel, 2: ACTIONS.prev, 3: ACTIONS.next, 8: stopNow };
  for (const [i, fn] of Object.entries(edges)) {
    if (pressed(+i) && !padPrev[i]) fn();
  }
  padPrev = pad.buttons.map((b) => b.pressed);
  requestAnimationFrame(pollPad);
}
addEventListener("gamepadconnected", startPad);

// --- the 3D view ----------------------------------------------------------------------------

let viewUrl = null;
let viewToken = null;  // the lease token the loaded 3D view was handed (syncViewLease)

// The name of what draws WebGL here, if it is software (no GPU), else null.
const softwareGL = (() => {
  try {
    const gl = document.createElement("canvas").getContext("webgl");
    const ext = gl && gl.getExtension("WEBGL_debug_renderer_info");
    const name = ext ? String(gl.getParameter(ext.UNMASKED_RENDERER_WEBGL)) : "";
    return (/SwiftShader|llvmpipe|softpipe|Software/i.exec(name) || [null])[0];
  } catch { return null; }
})();

// The 3D view's address with its detail: our copy of viser's client page (at "view"),
// connected to the viser server at viewUrl. "half" draws a quarter of the pixels, without
// multisampling. Without a GPU a full-detail frame takes 70-85 ms, and while the scene changes
// the browser spends most of the robot computer's CPU drawing (bench/view_load.py); the
// multisampling is half of a frame, and a click waits behind frames
// (bench/click_latency.py). So "auto" is half there and full elsewhere.
function viewSrc() {
  const half = settings.viewDetail === "half" || (settings.viewDetail === "auto" && softwareGL);
  const url = new URL("view", location.href);
  url.searchParams.set("websocket", viewUrl.replace(/^http/, "ws"));
  if (half) {
    url.searchParams.set("fixedDpr", "0.5");
    url.searchParams.set("multisample", "0");
  }
  return url.href;
}

function showView(on) {
  const frame = $("view");
  frame.hidden = !on;
  $("view-off").hidden = on;
  $("view-detail-note").textContent = softwareGL
    ? `This browser draws without a GPU (${softwareGL}): "auto" is half detail.`
    : "This browser draws with a GPU: \"auto\" is full detail.";
  // Hidden means not loaded: software WebGL would spend the robot computer's CPU for nothing.
  if (!on) frame.removeAttribute("src");
  else if (viewUrl) {
    if (token !== viewToken) { viewToken = token; leaseCookie(token || ""); }
    const src = viewSrc();
    if (frame.getAttribute("src") !== src) frame.src = src;
  }
}
// The 3D view's controls act only for the operator who holds control (unless it is this
// computer's own screen, connected straight to a server without a password): the page hands
// the view its lease token in a cookie that the view's websocket handshake carries (scoped to
// that websocket's path; never in an address, which access logs keep), and reloads the view
// when its token changes, so that the view acts for this page's lease.
function leaseCookie(value) {
  const url = new URL(viewUrl);
  const path = url.pathname.replace(/\/+$/, "") || "/";
  const secure = url.protocol === "https:" || url.protocol === "wss:" ? "; Secure" : "";
  const life = value ? "" : "; Max-Age=0";
  document.cookie = `laserpick_lease=${value}; Path=${path}; SameSite=Strict${secure}${life}`;
}
function syncViewLease() {
  if (!viewUrl || token === viewToken) return;
  viewToken = token;
  leaseCookie(token || "");
  const frame = $("view");
  if (!token || !frame.getAttribute("src")) return;
  try { frame.contentWindow.location.reload(); } catch { frame.src = frame.getAttribute("src"); }
}
setInterval(syncViewLease, 150);

async function findView() {
  try {
    const h = await (await fetch(`${API}/health`)).json();
    if (typeof h.max_nudge === "number" && h.max_nudge > 0) maxNudge = h.max_nudge;
    if (h.viser_url) viewUrl = new URL(h.viser_url, location.href).href;
    else if (h.viser_port) viewUrl = `${location.protocol}//${location.hostname}:${h.viser_port}/`;
  } catch { /* retried below */ }
  if (!viewUrl) { setTimeout(findView, 2000); return; }
  showView(settings.showView);
}
// The view is same-origin (/view): let Esc stop from inside it too.
$("view").addEventListener("load", () => {
  try {
    $("view").contentWindow.addEventListener("keydown", (e) => {
      if (e.key === "Escape") stopNow();
    }, true);
  } catch { /* another origin: its own STOP button serves */ }
});

// --- wiring ---------------------------------------------------------------------------------

function wire() {
  // An unavailable control explains itself instead of acting (capture: before any handler).
  document.addEventListener("click", (e) => {
    const el = e.target.closest("button");
    if (el && el.getAttribute("aria-disabled") === "true") {
      e.preventDefault();
      e.stopImmediatePropagation();
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
        if (latest) el.value = latest[el.dataset.mode];  // refused: show what holds
      }
    });
  }
  for (const el of document.querySelectorAll("[data-setting]")) {
    el.addEventListener("change", () => readSetting(el));
  }
  $("user").addEventListener("change", () => {
    user = $("user").value.trim().slice(0, 40) || "operator";
    settings = loadSettings(user);
    saveSettings();
    showSettings();
    token = null;  // the lease carries the user's name: take it again on the next command
  });
  for (const k of ["key1", "key2"]) {
    $(k).addEventListener("click", () => {
      listeningFor = k;
      $(k).classList.add("listening");
      $(k).textContent = `Press the new key for switch ${k.slice(-1)}… (Tab: keep ${keyName(settings[k])})`;
    });
  }
  // Take control is the lease form's submit button (Enter in the password field submits).
  $("lease").addEventListener("submit", (e) => e.preventDefault());
  if (!canSpeak) {
    $("speech").disabled = true;
    $("speech-note").hidden = false;
  }
  for (const b of document.querySelectorAll(".scan-back")) b.addEventListener("click", exitGroup);
  // Until the first state frame, only STOP is available.
  for (const el of document.querySelectorAll("button:not(#stop):not(#take):not(.keybind):not(.scan-back), [data-mode]")) {
    setAvailable(el, false);
  }
  if (connectedPads().length) startPad();
}

// Keep focused controls clear of the sticky bar, whatever its height (WCAG 2.4.11).
new ResizeObserver(() => {
  document.documentElement.style.setProperty("--bar-h", `${document.querySelector(".bar").offsetHeight}px`);
}).observe(document.querySelector(".bar"));

wire();
showSettings();
findView();
connect();
