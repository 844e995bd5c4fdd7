"""Periodic 3D gradient noise in float64: the reference of ``shaders/lib/gradient_noise.glsl``, which
the fog's turbulence and the clouds' detail noise both build on.

The lattice has ``period`` cells per tile on every axis; each corner's gradient is one of Perlin's 12
cube-edge vectors, picked by :func:`atmos.hashing.hash_counter` of the wrapped cell index, exactly as
the GLSL; the blend is the quintic fade.
"""
from __future__ import annotations

import numpy as np

from atmos.hashing import hash_counter

GRADIENTS = np.array([(1, 1, 0), (-1, 1, 0), (1, -1, 0), (-1, -1, 0), (1, 0, 1), (-1, 0, 1),
                      (1, 0, -1), (-1, 0, -1), (0, 1, 1), (0, -1, 1), (0, 1, -1), (0, -1, -1)], np.float64)


def _fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def periodic_noise(q, period: int, key) -> np.ndarray:
    """float64 noise at lattice coordinates ``q`` (..., 3); periodic with ``period`` on every axis."""
    q = np.asarray(q, np.float64)
    q = q - period * np.floor(q / period)
    c = np.floor(q)
    f = q - c
    i = c.astype(np.int64)
    u = _fade(f)
    total = np.zeros(q.shape[:-1])
    for corner in np.ndindex(2, 2, 2):
        w = (i + corner) % period
        counter = w[..., 0] + period * (w[..., 1] + period * w[..., 2])
        g = GRADIENTS[hash_counter(counter, *key) % np.uint32(12)]
        weight = np.prod(np.where(np.array(corner, bool), u, 1.0 - u), axis=-1)
        total += weight * np.sum(g * (f - corner), axis=-1)
    return total


def sample_repeat_trilinear(volume: np.ndarray, u) -> np.ndarray:
    """GL ``texture()`` of ``volume`` [x, y, z] at normalised ``u`` (..., 3): repeat wrap, linear filter."""
    shape = np.array(volume.shape)
    x = np.asarray(u, np.float64) * shape - 0.5
    i0 = np.floor(x).astype(np.int64)
    t = x - i0
    out = np.zeros(x.shape[:-1])
    for corner in np.ndindex(2, 2, 2):
        idx = (i0 + corner) % shape
        weight = np.prod(np.where(np.array(corner, bool), t, 1.0 - t), axis=-1)
        out += weight * volume[idx[..., 0], idx[..., 1], idx[..., 2]]
    return out
