"""Procedural stars in float64 numpy, the same arithmetic as ``shaders/sky/stars.glsl``.

The stars are fixed in world direction space: a direction picks a cell of a cube-map grid
(``STAR_GRID`` cells per face side); each cell's counter-based hash (:mod:`atmos.hashing`, bit for
bit as on the GPU) decides whether it holds a star, where in the cell's middle it sits, how bright
it is, its tint and how it twinkles. Cells on a face's border hold none, so no star straddles two
faces. A star is a Gaussian in cell units, filtered to the pixel footprint so that it never
flashes as the camera turns: its width is ``sqrt(STAR_SIGMA² + (FOOTPRINT · pixel)²)`` (the pixel
measured in cells where the star is, at most ``STAR_SIGMA_MAX``) and its peak falls as the width
grows, keeping each star's total light; a pixel sums the stars of its own cell and the eight
around it, each tapered to 0 from ``STAR_CUT`` cells out (inside what those nine cells can hold).
Twinkling is periodic in ``TWINKLE_PERIOD`` so the time can be wrapped and the phase stays precise
in float32. Stars fade in as the sun sets and out toward the horizon.
"""
from __future__ import annotations

import math

import numpy as np

from atmos.glsl_math import smoothstep
from atmos.hashing import hash_counter, lowbias32

STAR_GRID = 200                     # cells per cube-face side (about 0.45° each)
STAR_KEY = (0x2545F491, 0x6A09E667)  # hash stream of the star field
STAR_SIGMA = 0.05                   # star radius (Gaussian sigma), cells
FOOTPRINT = 0.6                     # a star is at least this many pixels wide (sigma): sampled without flashing
STAR_SIGMA_MAX = 0.33               # widest a star gets for coarse pixels, cells
STAR_CUT = (1.0, 1.3)               # the Gaussian is tapered to 0 over these distances, cells (the 3×3 cells
                                    # around a pixel hold every star within 1.3 cells: jitter ≥ 0.3)
STAR_NIGHT = (-0.18, -0.05)         # stars fade in as the sun's height (sin elevation) drops through this
STAR_HORIZON = 0.15                 # ... and in over view heights 0..STAR_HORIZON
TWINKLE_PERIOD = 64.0               # seconds after which the twinkling repeats (time is wrapped to it)
TWINKLE_CYCLES = (32, 96)           # each star twinkles a whole number of times in that period
TINTS = (np.array([1.0, 0.82, 0.65]), np.array([0.75, 0.85, 1.0]))



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


def pixel_cells(v: np.ndarray, pixel_angle: float) -> np.ndarray:
    """How many star cells one pixel spans at unit directions ``v``: the gnomonic face magnifies
    angles by ``major^-1.5`` (the geometric mean of its radial and tangential scales)."""
    major = np.max(np.abs(v), axis=-1)
    return pixel_angle * (0.5 * STAR_GRID) / major ** 1.5


def star_field(view_dir, sun_y: float, time: float, pixel_angle: float, density: float,
               brightness: float, twinkle: float) -> np.ndarray:
    """(..., 3) star radiance for unit view directions; ``pixel_angle``: radians per pixel (0: none)."""
    v = np.asarray(view_dir, np.float64)
    face, p, cell = cube_cell(v)
    sigma = np.minimum(np.sqrt(STAR_SIGMA ** 2 + (FOOTPRINT * pixel_cells(v, pixel_angle)) ** 2), STAR_SIGMA_MAX)
    peak = brightness * (STAR_SIGMA / sigma) ** 2
    t = float(time) % TWINKLE_PERIOD
    lo, hi = TWINKLE_CYCLES
    total = np.zeros(v.shape)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            c = cell + np.array([dx, dy])
            inner = np.all((c >= 1) & (c <= STAR_GRID - 2), axis=-1)      # border cells hold no star
            counter = (face * STAR_GRID * STAR_GRID + c[..., 1] * STAR_GRID + c[..., 0]).astype(np.int64)
            h0 = hash_counter(np.where(inner, counter, 0), *STAR_KEY)
            h1 = lowbias32(h0)
            h2 = lowbias32(h1)
            h3 = lowbias32(h2)
            present = inner & ((h0 & np.uint32(0xFFFF)) < np.uint32(star_threshold(density)))
            jitter = 0.3 + 0.4 * np.stack([_unit16(h1, 0), _unit16(h1, 16)], axis=-1)
            d = np.linalg.norm(p - (c + jitter), axis=-1)
            profile = np.exp(-0.5 * (d / sigma) ** 2) * (1.0 - smoothstep(*STAR_CUT, d))
            bright = 0.05 + 0.95 * _unit16(h2, 0) ** 8
            cycles = lo + (h3 & np.uint32(0xFFFF)) % np.uint32(hi - lo)
            tw = 1.0 + twinkle * np.sin(2.0 * math.pi * np.mod(cycles * t / TWINKLE_PERIOD + _unit16(h2, 16), 1.0))
            tint = TINTS[0] + (TINTS[1] - TINTS[0]) * _unit16(h3, 16)[..., None]
            total += np.where(present, bright * tw * profile, 0.0)[..., None] * tint
    fade = (1.0 - smoothstep(*STAR_NIGHT, sun_y)) * smoothstep(0.0, STAR_HORIZON, v[..., 1])
    return (peak * fade)[..., None] * total
