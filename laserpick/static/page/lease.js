// The control lease and the commands sent under it: take the lease (with the operator
// password when the server asks for one), send a command with the lease's token, give the
// lease back when the page goes away.
import { alertText, clearAlert } from "./announce.js";
import { API, describe, refusal } from "./api.js";
import { $ } from "./dom.js";
import { noteRtt } from "./latency.js";
import { renderLease } from "./render.js";
import { holderName } from "./settings.js";
import { shared } from "./shared.js";
import { heartbeat } from "./socket.js";

let taking = null;  // the request for the lease in flight: commands sent meanwhile share it

export function takeControl() {
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
    shared.token = data.token;
    heartbeat();
    renderLease();
    return true;
  }
  shared.token = null;
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
export async function command(path, body, method = "POST", retried = false) {
  if (!shared.token && !(await takeControl())) return null;
  const headers = { Authorization: `Bearer ${shared.token}` };
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
    shared.token = null;
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

// Give the lease back when the page goes away (keepalive: the request outlives the page).
export function giveBackLease() {
  if (shared.token) {
    fetch(`${API}/control`, {
      method: "DELETE", headers: { Authorization: `Bearer ${shared.token}` }, keepalive: true,
    }).catch(() => {});
  }
}
