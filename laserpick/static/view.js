// Runs first in the 3D view's page (viser's client, served at /view; see
// laserpick/console/view_page.py). With "multisample=0" in the address, which the console page
// asks for at half detail, WebGL draws without multisampling: without a GPU it took about half
// of every frame, and a click waits behind the frames (bench/click_latency.py).
"use strict";
if (new URLSearchParams(location.search).get("multisample") === "0") {
  const getContext = HTMLCanvasElement.prototype.getContext;
  HTMLCanvasElement.prototype.getContext = function (type, attributes) {
    if (typeof type === "string" && type.startsWith("webgl")) {
      attributes = { ...(attributes || {}), antialias: false };
    }
    return getContext.call(this, type, attributes);
  };
}
