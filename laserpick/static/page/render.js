// Rendering the state frame in the panel and the bar: at most 10 times a second, touching
// only what changed. Also what the bar says of the lease, and of a lost connection.
import { alertText, speak } from "./announce.js";
import { API } from "./api.js";
import { $ } from "./dom.js";
import { holderName } from "./settings.js";
import { AIMABLE, shared } from "./shared.js";

let renderTimer = null;
export function scheduleRender() {
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
  const s = shared.latest;
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

// The events websocket closed: say so until it is back.
export function renderOffline() {
  $("state-badge").textContent = "offline";
  $("status").textContent = seen.status = "Not connected to the robot. Retrying…";
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
export function setAvailable(el, ok) {
  const v = ok ? "false" : "true";
  if (el.getAttribute("aria-disabled") !== v) el.setAttribute("aria-disabled", v);
}

export function renderLease() {
  const { token, latest } = shared;
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
