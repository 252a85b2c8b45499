// The gamepad, polled with requestAnimationFrame only while one is connected (standard
// mapping): the left stick aims the laser at a rate; with the dead-man (RB) held, it drives.
// A: Detect or Go; B: Cancel; X, Y: previous, next grasp; Back: STOP.
import { ACTIONS, primary } from "./actions.js";
import { setDrive } from "./drive.js";
import { stopNow } from "./estop.js";
import { nudge } from "./nudge.js";
import { AIMABLE, shared } from "./shared.js";

const PAD_RATE = 0.5;     // rad/s: the laser's turn rate at full stick
const PAD_DEAD = 0.2;     // stick dead zone (of full travel)
const PAD_DEADMAN = 5;    // RB, standard mapping: hold for any drive motion

let padPolling = false;
let padPrev = [];
let padT = 0;
let padDriving = false;

const deadZone = (v) => (Math.abs(v) < PAD_DEAD ? 0 : Math.sign(v) * (Math.abs(v) - PAD_DEAD) / (1 - PAD_DEAD));
export function connectedPads() {
  return [...(navigator.getGamepads ? navigator.getGamepads() : [])].filter((p) => p && p.connected !== false);
}
export function startPad() {
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
  const latest = shared.latest;
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

export function watchPads() {
  addEventListener("gamepadconnected", startPad);
}
