"""A tileable blue-noise pattern: per-pixel offsets with neither low frequencies nor a direction.

:func:`blue_noise` ranks the pixels of a square tile by Ulichney's void-and-cluster method (1993): a
Gaussian (``sigma`` pixels, wrapped) measures how crowded each pixel's neighbourhood is; a random
start is relaxed until its tightest cluster is its largest void, then pixels are ranked by removing
the tightest clusters (down from the start's count) and adding into the largest voids (up to the
whole tile). Value ``(rank + 0.5) / size²``: every value once, uniform, and any threshold of it is
evenly spread. The cloud march and the light shafts' march offset their first samples by it
(:func:`blue_noise_texture`, ``texelFetch(blue_noise, pixel % size)``):
interleaved gradient noise, the cloud march's before, is a set of diagonal lines, which a moving
camera's reprojected history drew as a woven hatching; the shafts' white noise clumped.
"""
from __future__ import annotations

from functools import lru_cache

import moderngl
import numpy as np


def _kernel(size: int, sigma: float) -> np.ndarray:
    d = np.minimum(np.arange(size), size - np.arange(size)).astype(np.float64)
    return np.exp(-(d[:, None] ** 2 + d[None, :] ** 2) / (2.0 * sigma * sigma))


@lru_cache(maxsize=4)
def blue_noise(size: int = 64, sigma: float = 1.5, seed: int = 0) -> np.ndarray:
    """(size, size) float32 in (0, 1), each (k + 0.5) / size² once, tileable (module docstring)."""
    n = size * size
    kernel = _kernel(size, sigma)
    shifted = lambda i: np.roll(np.roll(kernel, i // size, 0), i % size, 1).ravel()
    rng = np.random.default_rng(seed)
    ones = np.zeros(n, bool)
    ones[rng.choice(n, max(1, n // 10), replace=False)] = True
    energy = sum(shifted(i) for i in np.flatnonzero(ones))
    for _ in range(n):                          # relax: the tightest cluster moves to the largest void
        cluster = int(np.argmax(np.where(ones, energy, -np.inf)))
        ones[cluster] = False
        energy -= shifted(cluster)
        void = int(np.argmin(np.where(ones, np.inf, energy)))
        ones[void] = True
        energy += shifted(void)
        if void == cluster:
            break
    rank = np.zeros(n, np.int64)
    start, start_energy = ones.copy(), energy.copy()
    for r in range(int(ones.sum()) - 1, -1, -1):  # down: remove the tightest clusters
        cluster = int(np.argmax(np.where(ones, energy, -np.inf)))
        rank[cluster] = r
        ones[cluster] = False
        energy -= shifted(cluster)
    ones, energy = start, start_energy
    for r in range(int(ones.sum()), n):           # up: fill the largest voids
        void = int(np.argmin(np.where(ones, np.inf, energy)))
        rank[void] = r
        ones[void] = True
        energy += shifted(void)
    return ((rank + 0.5) / n).reshape(size, size).astype(np.float32)


def blue_noise_texture(ctx):
    """A new r32f texture of :func:`blue_noise` on the moderngl context ``ctx`` (texel (x, y) =
    tile[y, x], nearest); the pass that made it releases it."""
    tile = blue_noise()
    texture = ctx.texture(tile.shape[::-1], 1, tile.tobytes(), dtype="f4")
    texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return texture
