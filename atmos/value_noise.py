"""Value noise and rotated FBM in numpy float64: the reference of ``shaders/lib/value_noise.glsl``.

Lattice values are bit for bit those of the GLSL (lowbias32 chain, top 24 bits / 2^24), so GPU and
reference differ only by float32 rounding of positions and blends.
"""
from __future__ import annotations

import numpy as np

from atmos.hashing import lowbias32

ROTATION = np.array([[0.00, 0.80, 0.60],
                     [-0.80, 0.36, -0.48],
                     [-0.60, -0.48, 0.64]]).T     # GLSL mat3 columns -> numpy matrix
_SEED_SALT = 0x9E3779B9
LIMIT = 2147483520.0        # octaves with |coordinate| >= this (beyond int32) are dropped, as in GLSL


def key(seed: int) -> np.uint32:
    """The lattice key of ``seed`` (GLSL ``vn_key``)."""
    return lowbias32(np.uint32(seed) ^ np.uint32(_SEED_SALT))


def lattice(cells: np.ndarray, k, period: int | None = None) -> np.ndarray:
    """Values in [0, 1) of integer lattice points ``cells`` (..., D) for key ``k``; with a ``period``
    (a power of two) those of the cells mod ``period``: a lattice that repeats."""
    cells = np.asarray(cells, np.int64)
    if period is not None:
        cells = cells & (period - 1)
    h = lowbias32((cells[..., 0] & 0xFFFFFFFF) ^ int(k))
    for axis in range(1, cells.shape[-1]):
        h = lowbias32(h ^ (cells[..., axis] & 0xFFFFFFFF).astype(np.uint32))
    return (h >> np.uint32(8)).astype(np.float64) / 16777216.0


def value_noise(x: np.ndarray, k, period: int | None = None) -> np.ndarray:
    """D-dimensional value noise (D = x.shape[-1]) with smoothstep weights, in [0, 1) (on the lattice
    repeating every ``period`` cells, if given)."""
    x = np.asarray(x, np.float64)
    p = np.floor(x)
    f = x - p
    f = f * f * (3.0 - 2.0 * f)
    c = p.astype(np.int64)
    dims = x.shape[-1]
    values = {}
    for corner in np.ndindex(*(2,) * dims):
        values[corner] = lattice(c + np.array(corner), k, period)
    for axis in range(dims):              # blend x first, then y, z, w like the GLSL
        t = f[..., axis]
        values = {rest: values[(0,) + rest] * (1 - t) + values[(1,) + rest] * t
                  for rest in {c[1:] for c in values}}
    return values[()]


def fbm(points: np.ndarray, octaves: int, seed: int = 0, period: int | None = None) -> np.ndarray:
    """Σ_i 2^-(i+1) noise(p_i), p_0 = p, p_{i+1} = R p_i (2 + i/10); points shape (..., 3); every octave
    on the lattice repeating every ``period`` cells, if given (the volumetric fog's baked lattice).

    A point stops adding octaves once a coordinate reaches ``LIMIT`` (like the GLSL).
    """
    p = np.asarray(points, np.float64)
    k = key(seed)
    total = np.zeros(p.shape[:-1])
    live = np.ones(p.shape[:-1], bool)
    amp = 1.0
    for i in range(octaves):
        live &= (np.abs(p) < LIMIT).all(axis=-1)
        amp *= 0.5
        total += np.where(live, amp * value_noise(np.where(live[..., None], p, 0.0), k, period), 0.0)
        p = (p @ ROTATION.T) * (2.0 + i / 10.0)
    return total
