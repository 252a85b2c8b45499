// The e-stop, from every input (the STOP button, Esc anywhere on the page or in the 3D view,
// the gamepad's Back): the page's own driving and pending nudges end first, then POST /stop.
import { alertText } from "./announce.js";
import { API } from "./api.js";
import { stopDriving } from "./drive.js";
import { noteRtt } from "./latency.js";
import { dropNudges } from "./nudge.js";
import { shared } from "./shared.js";

// The e-stop needs no token: anyone watching may stop the robot.
export async function stopNow() {
  stopDriving(false);
  dropNudges();
  const headers = shared.token ? { Authorization: `Bearer ${shared.token}` } : {};
  const t0 = performance.now();
  try {
    const r = await fetch(`${API}/stop`, { method: "POST", headers });
    noteRtt(performance.now() - t0, true);
    alertText(r.ok ? "STOP: motion halted." : `STOP failed: error ${r.status}.`);
  } catch {
    alertText("STOP could not reach the server!");
  }
}
