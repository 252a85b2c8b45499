// What several modules read and write, in one place: the page's lease token, the newest
// state frame, the server's nudge limit; and the robot states in which the laser may be aimed.

// The server's AIMABLE.
export const AIMABLE = new Set(["idle", "aiming", "perceived", "grasps_ready", "holding", "awaiting_place"]);

export const shared = {
  token: null,   // the control lease's token; null while the page holds none
  latest: null,  // the newest state frame (the events websocket's)
  // rad: the server's largest nudge per command, from GET /health; null until the server says
  // (a server that does not say is not second-guessed here).
  maxNudge: null,
};
