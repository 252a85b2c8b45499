"""Colour statistics of a screenshot, computed in the browser (no image library needed)."""

from __future__ import annotations

import base64
from typing import Any

# Colour statistics of a PNG, computed in the browser (no image library needed here):
# the shares of pixels of the scooter's red shell, of the projector's yellow light and of
# green grasp outlines, and the number of distinct colours (4 bits per channel) that cover at
# least 0.2 % of the image.
PNG_STATS_JS = """
async (b64) => {
  const img = new Image();
  img.src = "data:image/png;base64," + b64;
  await img.decode();
  const c = document.createElement("canvas");
  c.width = img.width; c.height = img.height;
  const ctx = c.getContext("2d");
  ctx.drawImage(img, 0, 0);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  const n = c.width * c.height;
  const bins = new Map();
  let red = 0, lit = 0, green = 0;
  for (let i = 0; i < d.length; i += 4) {
    const r = d[i], g = d[i + 1], b = d[i + 2];
    if (r > 120 && r - g > 80 && r - b > 80 && Math.abs(g - b) < 40) red++;
    if (r > 230 && g > 210 && b > 80 && b < 170) lit++;  // the projector's yellow light
    if (g > 150 && g - r > 60 && g - b > 80) green++;  // a high-scoring grasp outline
    const k = ((r >> 4) << 8) | ((g >> 4) << 4) | (b >> 4);
    bins.set(k, (bins.get(k) || 0) + 1);
  }
  let colours = 0;
  for (const v of bins.values()) if (v >= 0.002 * n) colours++;
  return {
    red: red / n, lit: lit / n, green: green / n, colours: colours,
    width: c.width, height: c.height,
  };
}
"""


def pixel_stats(page: Any, png: bytes) -> dict:
    """`PNG_STATS_JS` of a PNG, run in the Playwright `page`."""
    return page.evaluate(PNG_STATS_JS, base64.b64encode(png).decode())
