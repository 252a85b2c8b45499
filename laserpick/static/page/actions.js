// The panel's buttons, by id (ACTIONS), and what moves the task on (the gamepad's A).
import { stopNow } from "./estop.js";
import { stopDriving } from "./drive.js";
import { command, takeControl } from "./lease.js";
import { settings } from "./settings.js";
import { shared } from "./shared.js";

// Detect: light both beams (confirm), or, once the target is perceived, find grasps again.
function detect() {
  const st = shared.latest && shared.latest.state;
  if (st === "perceived" || st === "grasps_ready") return command("/detect");
  return command("/laser/confirm");
}
// The gamepad's A: whatever moves the task on.
export function primary() {
  const st = shared.latest && shared.latest.state;
  if (st === "grasps_ready" || st === "holding") return command("/execute");
  return detect();
}

// Stepping to another grasp makes the choice manual first, so that Go picks the grasp shown
// (as the switch and joystick adapters do); Auto goes back to the system's choice.
async function stepGrasp(dir) {
  const latest = shared.latest;
  if (latest && latest.selection === "auto" && !(await command("/mode", { selection: "manual" }))) return;
  await command(`/grasps/${dir}`, { level: settings.level });
}
async function autoGrasp() {
  if ((await command("/grasps/auto")) && shared.latest && shared.latest.selection !== "auto") {
    await command("/mode", { selection: "auto" });
  }
}

export const ACTIONS = {
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
