"""The depth sensors' noise: a seeded generator of Gaussian noise (sliced from a pool drawn once)
and smooth random fields, and the noise model that turns exact depth into a sensor's depth."""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np

from laserpick.description import dims
from laserpick.settings import SensorSettings

#: Size of the pool of Gaussian samples the per-pixel noise is sliced from (see _normal).
NOISE_POOL = 1 << 22


class SensorNoise:
    """The sensors' random numbers, from one generator seeded with `seed`: the same seed and
    the same sequence of calls give the same numbers."""

    def __init__(self, seed: int | np.random.SeedSequence | None) -> None:
        self._rng = np.random.default_rng(seed)
        self._pool: np.ndarray | None = None  # see normal

    def reseed(self, seed: int | np.random.SeedSequence) -> None:
        """Draw from here on as a fresh generator seeded with `seed` would."""
        self._rng = np.random.default_rng(seed)
        self._pool = None

    def normal(self, shape: tuple[int, int]) -> np.ndarray:
        """Standard normal float32 noise of `shape`: a slice at a random offset of a pool drawn
        once. Drawing 300k normals costs ~5 ms, twice per camera; the slice costs nothing.
        Pixels within a frame stay independent; frames reuse the pool at shifted offsets."""
        n = shape[0] * shape[1]
        if self._pool is None:
            self._pool = self._rng.standard_normal(NOISE_POOL, dtype=np.float32)
        o = int(self._rng.integers(0, self._pool.size - n))
        return self._pool[o : o + n].reshape(shape)

    def blob_field(self, pixels: np.ndarray, H: int, W: int, cell: float) -> np.ndarray:
        """A smooth random field sampled at flat pixel indices: Gaussian values on a grid of
        `cell`-pixel cells, interpolated bilinearly. Draws the whole grid each time so the
        generator advances by the same amount whatever the pixels are."""
        gh, gw = math.ceil(H / cell) + 2, math.ceil(W / cell) + 2
        grid = self._rng.standard_normal((gh, gw))
        y = (pixels // W) / cell
        x = (pixels % W) / cell
        y0, x0 = np.floor(y).astype(np.int64), np.floor(x).astype(np.int64)
        fy, fx = y - y0, x - x0
        return (
            grid[y0, x0] * (1 - fy) * (1 - fx)
            + grid[y0, x0 + 1] * (1 - fy) * fx
            + grid[y0 + 1, x0] * fy * (1 - fx)
            + grid[y0 + 1, x0 + 1] * fy * fx
        )


def noisy_depth(
    z_true: np.ndarray,
    seg: np.ndarray,
    settings: SensorSettings,
    noise: SensorNoise,
    specular: np.ndarray,
    has_specular: bool,
) -> np.ndarray:
    """The sensor's depth (H, W) float32 m, 0 = missing, from the exact z-depth `z_true` and
    the geom ids `seg` (-1: nothing); `specular` flags the specular geoms, (ngeom + 1,) with a
    trailing False for -1, and `has_specular` whether there are any."""
    s = settings
    H, W = z_true.shape
    drop = np.zeros((H, W), dtype=bool)
    # 1. Edges: both pixels of a neighbour pair across a jump (the empty far plane counts
    #    as far away, so silhouettes against nothing are edges too).
    if s.edge_dropout_prob > 0:
        jx = np.abs(np.diff(z_true, axis=1)) > s.edge_dropout_jump
        jy = np.abs(np.diff(z_true, axis=0)) > s.edge_dropout_jump
        edge = np.zeros((H, W), dtype=bool)
        edge[:, 1:] |= jx
        edge[:, :-1] |= jx
        edge[1:, :] |= jy
        edge[:-1, :] |= jy
        # An edge pixel drops with chance p: a standard normal below Phi^-1(p).
        p = s.edge_dropout_prob
        cut = np.float32(NormalDist().inv_cdf(p)) if p < 1 else np.float32(np.inf)
        drop = edge & (noise.normal((H, W)) < cut)
    # 2. Specular blobs.
    if has_specular and s.specular_dropout > 0:
        spec_px = np.flatnonzero(np.take(specular, seg))  # -1 picks the last False
        if spec_px.size:
            field = noise.blob_field(spec_px, H, W, float(s.specular_blob_px))
            ids = seg.flat[spec_px]
            for g in np.unique(ids):
                sel = ids == g
                thr = np.quantile(field[sel], s.specular_dropout)
                drop.flat[spec_px[sel][field[sel] <= thr]] = True
    # 3. Noise grows with z^2.
    z = z_true
    if s.depth_noise_k > 0:
        z_noise = noise.normal((H, W))
        z = z_true + z_noise * (np.float32(s.depth_noise_k) * z_true * z_true)
    # 4. Range.
    valid = (z >= dims.DEPTH_MIN) & (z <= dims.DEPTH_MAX) & ~drop
    return z * valid  # multiplying by the mask is 10x faster than np.where here
