// Laser nudges (rad), coalesced: keys repeat at 30 Hz and a stick moves continuously, but
// only one nudge is in flight at a time, carrying the sum of what came meanwhile, within the
// server's largest nudge per command.
import { command } from "./lease.js";
import { shared } from "./shared.js";

const pending = { dyaw: 0, dpitch: 0, busy: false };
export function nudge(dyaw, dpitch) {
  pending.dyaw += dyaw;
  pending.dpitch += dpitch;
  flushNudge();
}
async function flushNudge() {
  if (pending.busy || (Math.abs(pending.dyaw) < 1e-4 && Math.abs(pending.dpitch) < 1e-4)) return;
  const maxNudge = shared.maxNudge;
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

// Forget the nudges not sent yet (the e-stop).
export function dropNudges() {
  pending.dyaw = pending.dpitch = 0;
}
