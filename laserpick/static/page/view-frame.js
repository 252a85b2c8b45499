// The embedded 3D view (iframe#view): where it is (GET /health, which also gives the laser's
// nudge limit), its detail, hiding it, handing it the page's lease, and Esc inside it.
import { API } from "./api.js";
import { $ } from "./dom.js";
import { stopNow } from "./estop.js";
import { settings } from "./settings.js";
import { shared } from "./shared.js";

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

export function showView(on) {
  const frame = $("view");
  frame.hidden = !on;
  $("view-off").hidden = on;
  $("view-detail-note").textContent = softwareGL
    ? `This browser draws without a GPU (${softwareGL}): "auto" is half detail.`
    : "This browser draws with a GPU: \"auto\" is full detail.";
  // Hidden means not loaded: software WebGL would spend the robot computer's CPU for nothing.
  if (!on) frame.removeAttribute("src");
  else if (viewUrl) {
    const token = shared.token;
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
  const token = shared.token;
  if (!viewUrl || token === viewToken) return;
  viewToken = token;
  leaseCookie(token || "");
  const frame = $("view");
  if (!token || !frame.getAttribute("src")) return;
  try { frame.contentWindow.location.reload(); } catch { frame.src = frame.getAttribute("src"); }
}
export function keepViewLease() {
  setInterval(syncViewLease, 150);
}
// The page goes away: the view's cookie goes with it.
export function forgetViewLease() {
  if (viewUrl && viewToken) leaseCookie("");
}

export async function findView() {
  try {
    const h = await (await fetch(`${API}/health`)).json();
    if (typeof h.max_nudge === "number" && h.max_nudge > 0) shared.maxNudge = h.max_nudge;
    if (h.viser_url) viewUrl = new URL(h.viser_url, location.href).href;
    else if (h.viser_port) viewUrl = `${location.protocol}//${location.hostname}:${h.viser_port}/`;
  } catch { /* retried below */ }
  if (!viewUrl) { setTimeout(findView, 2000); return; }
  showView(settings.showView);
}
// The view is same-origin (/view): let Esc stop from inside it too.
export function stopFromView() {
  $("view").addEventListener("load", () => {
    try {
      $("view").contentWindow.addEventListener("keydown", (e) => {
        if (e.key === "Escape") stopNow();
      }, true);
    } catch { /* another origin: its own STOP button serves */ }
  });
}
