// The keyboard, heard on the window in the capture phase: Esc stops whatever has the focus,
// and the switch keys never reach (and press) the focused control. The arrows nudge the laser
// (Shift: finely) or, with the focus in the Drive group or "Arrows drive" on, drive while held.
import { $ } from "./dom.js";
import { driveKeyDown, driveKeyUp } from "./drive.js";
import { stopNow } from "./estop.js";
import { nudge } from "./nudge.js";
import { switchDown, switchUp } from "./scanning.js";
import { settings } from "./settings.js";
import { AIMABLE, shared } from "./shared.js";
import { endListening, isListening, takeKey } from "./switch-keys.js";

const FINE_STEP = 0.01;   // rad: Shift+arrow
const ARROWS = { ArrowUp: [0, 1], ArrowDown: [0, -1], ArrowLeft: [1, 0], ArrowRight: [-1, 0] };

const isTyping = (el) => el && (el.tagName === "TEXTAREA"
  || (el.tagName === "INPUT" && !["checkbox", "radio", "button"].includes(el.type)));
function switchOf(e) {
  if (settings.scanMode === "off" || isTyping(e.target) || isListening()) return 0;
  if (e.code === settings.key1) return 1;
  if (e.code === settings.key2 && settings.scanMode === "step") return 2;
  return 0;
}

function keyDown(e) {
  if (e.key === "Escape") {
    e.preventDefault();
    if (isListening()) endListening();
    stopNow();
    return;
  }
  if (isListening()) {
    if (e.key === "Tab") { endListening(); return; }  // Tab stays for moving on
    e.preventDefault();
    takeKey(e.code);
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
  const latest = shared.latest;
  if ($("arrows-drive").checked || $("g-drive").contains(e.target)) {
    if (!e.repeat) driveKeyDown(e.key);
  } else if (latest && AIMABLE.has(latest.state) && !latest.busy) {
    const [sy, sp] = ARROWS[e.key];
    const step = e.shiftKey ? FINE_STEP : +settings.step;
    nudge(sy * step, sp * step);
  }
}

function keyUp(e) {
  const sw = switchOf(e);
  if (sw) { e.preventDefault(); e.stopPropagation(); switchUp(); return; }
  driveKeyUp(e.key);
}

export function listenToKeys() {
  addEventListener("keydown", keyDown, true);
  addEventListener("keyup", keyUp, true);
}
