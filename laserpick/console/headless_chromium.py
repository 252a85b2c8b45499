"""Debian's Chromium, headless, for the console's browser tests and benchmarks.

Playwright drives the system browser (it may not download its own here). The flags keep
Chromium off the network, which this machine does not have, and give it WebGL without a GPU
through ANGLE on SwiftShader.
"""

from __future__ import annotations

from typing import Any

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = (
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
)


def launch(playwright: Any, **kwargs: Any) -> Any:
    """Start headless Chromium with `playwright` (the sync API's object); returns the Browser."""
    return playwright.chromium.launch(executable_path=CHROMIUM, args=list(CHROMIUM_ARGS), **kwargs)
