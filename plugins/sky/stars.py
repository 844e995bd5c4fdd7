"""Procedural stars in float64 numpy, the same arithmetic as ``shaders/sky/stars.glsl``.

The view direction picks a cell of a cube-map grid (``STAR_GRID`` cells per face side); the cell's
counter-based hash (:mod:`atmos.hashing`, bit for bit as on the GPU) decides whether it holds a star,
where in the cell's middle it sits, how bright it is, its tint and how it twinkles. A star is a
Gaussian in cell units that is exactly 0 from ``STAR_CUT`` cells out, well inside its own cell, so
a direction on a cell border never sees a star (float32 and float64 agree there). Twinkling is
periodic in ``TWINKLE_PERIOD`` so the time can be wrapped and the phase stays precise in float32. Stars smaller than
a pixel are widened to half a pixel with the same total light; they fade in as the sun sets and out
toward the horizon.
"""
from __future__ import annotations

import math

import numpy as np

from atmos.hashing import hash_counter, lowbias32

STAR_GRID = 200                     # cells per cube-face side (about 0.45° each)
STAR_KEY = (0x2545F491, 0x6A09E667)  # hash stream of the star field
STAR_SIGMA = 0.05                   # star radius (Gaussian sigma), cells
STAR_SIGMA_MAX = 0.1                # widest a star gets for coarse pixels, cells
STAR_CUT = (0.2, 0.3)               # the Gaussian is tapered to 0 over these distances, cells
STAR_NIGHT = (-0.18, -0.05)         # stars fade in as the sun's height (sin elevation) drops through this
STAR_HORIZON = 0.15                 # ... and in over view heights 0..STAR_HORIZON
TWINKLE_PERIOD = 64.0               # seconds after which the twinkling repeats (time is wrapped to it)
TWINKLE_CYCLES = (32, 96)           # each star twinkles a whole number of times in that period
TINTS = (np.array([1.0, 0.82, 0.65]), np.array([0.75, 0.85, 1.0]))


def smoothstep(e0, e1, x):
    t = np.clip((np.asarray(x, np.float64) - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def star_threshold(density: float) -> int:
    """Cells whose hash's low 16 bits are below this hold a star (the GLSL gets it as a uint)."""
    return int(round(float(density) * 65536.0))


def cube_cell(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(face 0..5, position in cell units (..., 2), cell (..., 2)) of unit directions ``v``."""
    a = np.abs(v)
    on_x = (a[..., 0] >= a[..., 1]) & (a[..., 0] >= a[..., 2])
    on_y = ~on_x & (a[..., 1] >= a[..., 2])
    face = np.where(on_x, np.where(v[..., 0] > 0, 0, 1),
                    np.where(on_y, np.where(v[..., 1] > 0, 2, 3), np.where(v[..., 2] > 0, 4, 5)))
    major = np.where(on_x, a[..., 0], np.where(on_y, a[..., 1], a[..., 2]))[..., None]
    pair = np.where(on_x[..., None], v[..., [1, 2]], np.where(on_y[..., None], v[..., [0, 2]], v[..., [0, 1]]))
    uv = pair / major
    p = (uv * 0.5 + 0.5) * STAR_GRID
    return face, p, np.clip(np.floor(p), 0, STAR_GRID - 1)


def _unit16(h, shift: int) -> np.ndarray:
    return ((h >> np.uint32(shift)) & np.uint32(0xFFFF)).astype(np.float64) / 65535.0


def star_field(view_dir, sun_y: float, time: float, pixel_angle: float, density: float,
               brightness: float, twinkle: float) -> np.ndarray:
    """(..., 3) star radiance for unit view directions; ``pixel_angle``: radians per pixel (0: none)."""
    v = np.asarray(view_dir, np.float64)
    face, p, cell = cube_cell(v)
    counter = (face * STAR_GRID * STAR_GRID + cell[..., 1] * STAR_GRID + cell[..., 0]).astype(np.int64)
    h0 = hash_counter(counter, *STAR_KEY)
    h1 = lowbias32(h0)
    h2 = lowbias32(h1)
    h3 = lowbias32(h2)
    present = (h0 & np.uint32(0xFFFF)) < np.uint32(star_threshold(density))
    jitter = 0.3 + 0.4 * np.stack([_unit16(h1, 0), _unit16(h1, 16)], axis=-1)
    d = np.linalg.norm(p - (cell + jitter), axis=-1)
    pixel_cells = pixel_angle * STAR_GRID / (0.5 * math.pi)
    sigma = max(STAR_SIGMA, min(0.5 * pixel_cells, STAR_SIGMA_MAX))
    profile = (STAR_SIGMA / sigma) ** 2 * np.exp(-0.5 * (d / sigma) ** 2) * (1.0 - smoothstep(*STAR_CUT, d))
    bright = 0.05 + 0.95 * _unit16(h2, 0) ** 8
    lo, hi = TWINKLE_CYCLES
    cycles = lo + (h3 & np.uint32(0xFFFF)) % np.uint32(hi - lo)
    t = float(time) % TWINKLE_PERIOD
    tw = 1.0 + twinkle * np.sin(2.0 * math.pi * np.mod(cycles * t / TWINKLE_PERIOD + _unit16(h2, 16), 1.0))
    tint = TINTS[0] + (TINTS[1] - TINTS[0]) * _unit16(h3, 16)[..., None]
    fade = (1.0 - smoothstep(*STAR_NIGHT, sun_y)) * smoothstep(0.0, STAR_HORIZON, v[..., 1])
    amount = np.where(present, brightness * bright * tw * profile * fade, 0.0)
    return amount[..., None] * tint
