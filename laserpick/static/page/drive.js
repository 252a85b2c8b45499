// Driving the base: hold to drive, click for one step. Each input (the on-screen pad's
// pointer, the arrow keys, the gamepad, a switch) holds a [forward, turn] wish in -1..1; the
// sum drives, at the Speed setting (m/s; turns in rad/s).
import { command } from "./lease.js";
import { settings } from "./settings.js";

const DRIVE_PERIOD = 250; // ms: a drive command is a 0.5 s dead-man, so resend at 4 Hz
const DRIVE_ARROWS = { ArrowUp: [1, 0], ArrowDown: [-1, 0], ArrowLeft: [0, 1], ArrowRight: [0, -1] };

const driveWish = new Map();
const driveKeys = new Set();  // the arrow keys held down to drive
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
// source: "pointer", "keys", "pad" or "switch"; wish: [f, t] or null to let go. coast: a
// short press (a click) lets its 0.5 s step run out instead of stopping at once.
export function setDrive(source, wish, coast = false) {
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
export const isDriving = (source) => driveWish.has(source);
export function stopDriving(send) {
  driveWish.clear();
  for (const b of document.querySelectorAll(".held")) b.classList.remove("held");
  if (driveTimer) {
    clearInterval(driveTimer);
    driveTimer = null;
    if (send) sendDrive(0, 0, 0.1);
  }
  lastSent = "0,0";
}
export function stopDrivingOnBlur() {
  addEventListener("blur", () => { driveKeys.clear(); if (driveWish.size) stopDriving(true); });
}

// --- the arrow keys: drive while held -----------------------------------------------------

function driveKeyWish() {
  let f = 0, t = 0;
  for (const k of driveKeys) { f += DRIVE_ARROWS[k][0]; t += DRIVE_ARROWS[k][1]; }
  return f || t ? [f, t] : null;
}
export function driveKeyDown(key) {
  driveKeys.add(key);
  setDrive("keys", driveKeyWish());
}
export function driveKeyUp(key) {
  if (driveKeys.delete(key)) setDrive("keys", driveKeyWish());
}

// --- the on-screen pad: hold a button to drive, a click drives one step -------------------

export function wireDrivePad() {
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
