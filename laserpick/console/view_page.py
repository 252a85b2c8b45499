"""The 3D view's page: viser's own client, served by the console's server at `/view`.

The page at `/` embeds this instead of the viser server's copy so that one script of ours
(`static/view.js`) runs ahead of the client: on a browser without a GPU it turns off WebGL's
multisampling at half detail. Software WebGL (SwiftShader) spent about half of each frame on
it, and a click waits behind those frames (bench/click_latency.py). The client connects to
the viser server named by its `websocket` query parameter, as viser's client does anywhere.
"""

from __future__ import annotations

import functools
from pathlib import Path

import viser

#: The single-file client that the installed viser serves itself.
VISER_CLIENT = Path(viser.__file__).parent / "client" / "build" / "index.html"
#: Our script, first in the head: before the client makes its WebGL context.
AHEAD = '<script src="static/view.js"></script>'


@functools.cache
def view_page() -> str:
    """viser's client page with `AHEAD` first in its head. RuntimeError when the installed
    viser has no built client, or no head to put the script in."""
    try:
        html = VISER_CLIENT.read_text(encoding="utf-8")
    except OSError as exc:
        raise RuntimeError(f"viser's client page is missing at {VISER_CLIENT}: {exc}") from exc
    head = html.find("<head>")
    if head < 0:
        raise RuntimeError(f"viser's client page at {VISER_CLIENT} has no <head>")
    head += len("<head>")
    return html[:head] + AHEAD + html[head:]
