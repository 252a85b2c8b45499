"""The API's binary bodies: the fused cloud (GET /cloud) and the projector image (GET
/projector.png)."""

from __future__ import annotations

import io

import numpy as np

#: GET /cloud: b"LPC1", then the point count N as uint32, then N x 3 float32 (x, y, z) in
#: `base` (m), all little-endian.
CLOUD_MAGIC = b"LPC1"
CLOUD_FORMAT = "LPC1 | uint32 N | N x (float32 x, y, z) in base, metres, little-endian"


def encode_cloud(points: np.ndarray) -> bytes:
    """(N, 3) points (m, `base`) in the GET /cloud format."""
    header = np.array([len(points)], dtype="<u4").tobytes()
    return CLOUD_MAGIC + header + np.asarray(points, dtype="<f4").tobytes()


def decode_cloud(data: bytes) -> np.ndarray:
    """The (N, 3) float32 points of a GET /cloud body; ValueError if it is not one."""
    if data[:4] != CLOUD_MAGIC or len(data) < 8:
        raise ValueError("not a laserpick cloud (bad magic)")
    n = int(np.frombuffer(data[4:8], dtype="<u4")[0])
    if len(data) != 8 + 12 * n:
        raise ValueError(f"a cloud of {n} points needs {8 + 12 * n} bytes, got {len(data)}")
    return np.frombuffer(data[8:], dtype="<f4").reshape(n, 3)


def encode_png(image: np.ndarray) -> bytes:
    """A grey (H, W) uint8 image as PNG (fast compression: it is served live)."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(image, mode="L").save(buf, format="PNG", optimize=False, compress_level=1)
    return buf.getvalue()
