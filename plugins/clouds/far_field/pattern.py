"""How the far field samples its four octave textures: each with its own turn and period, so the sum repeats nowhere.

Octave k's texture (period 1 in uv) holds ``base_frequency · 2^k · PERIODS[k]`` noise cells and is
sampled at ``uv_k = R(TURNS[k]) · xz / (tile_size · PERIODS[k]) + offset_k``: its cells keep the size
``tile_size / (base_frequency · 2^k)`` while it repeats every ``PERIODS[k] · tile_size`` metres along
axes turned by ``TURNS[k]``. The periods are powers of the golden ratio (6.9, 4.2, 2.6 and 1 tiles: a
texture keeps 6–9 texels per cell at 256 texels and base frequency 4) and the turns multiples of the
golden angle, so no lag repeats two octaves at once (with one period and no turn, the dominant octave
and with it the whole pattern repeated every tile: rows of the same clouds to the horizon). The
channels (CHANNEL_STEPS: the point, RELIEF_STEPS light steps toward the sun and as many away, the
point again) are baked along each octave's own turned axis (``OctaveTextures.bake`` with
``rotations()`` as its shift maps), so they stay toward the sun in the world: one fetch gives a
point's rank and the slope of the clouds across it along the sun (field.glsl far_relief).
"""
from __future__ import annotations

import numpy as np

GOLDEN = 0.5 * (1.0 + 5.0 ** 0.5)
TURNS = np.arange(4) * np.pi * (3.0 - 5.0 ** 0.5)          # k golden angles (rad)
PERIODS = GOLDEN ** np.array([4.0, 3.0, 2.0, 0.0])          # φ⁴, φ³, φ², 1 tiles: the coarse octaves repeat least
RELIEF_STEPS = 2.0                                          # light steps to the relief's samples, each way
CHANNEL_STEPS = (0.0, RELIEF_STEPS, -RELIEF_STEPS, 0.0)     # the baked channels' light steps toward the sun


def _rotations() -> np.ndarray:
    c, s = np.cos(TURNS), np.sin(TURNS)
    turns = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2) / PERIODS[:, None, None]
    turns.setflags(write=False)
    return turns


_ROTATIONS = _rotations()
_TURNS_F4 = np.transpose(_ROTATIONS, (0, 2, 1)).astype("f4").tobytes()     # column-major mat2[4]


def rotations() -> np.ndarray:
    """(4, 2, 2) R(TURNS[k]) / PERIODS[k]: world xz in tiles → octave k's uv (computed once, read-only)."""
    return _ROTATIONS


def turns_bytes() -> bytes:
    """:func:`rotations` as a GLSL ``mat2[4]`` (column-major float32)."""
    return _TURNS_F4


def octave_uv(xz, offsets, tile_size: float) -> np.ndarray:
    """(4, ..., 2) each octave's uv at world ``xz`` (..., 2): ``offsets`` (4, 2) in its uv (:func:`octave_offsets`)."""
    p = np.asarray(xz, np.float64) / float(tile_size)
    return np.einsum("kij,...j->k...i", rotations(), p) + np.asarray(offsets, np.float64).reshape((4,) + (1,) * (p.ndim - 1) + (2,))


def octave_offsets(metres, tile_size: float) -> np.ndarray:
    """(4, 2) each octave's uv of the world point ``metres`` (2,), wrapped to [0, 1) (float64)."""
    return np.mod(rotations() @ (np.asarray(metres, np.float64) / float(tile_size)), 1.0)


def octave_frequencies(base_frequency: int) -> np.ndarray:
    """(4,) noise cells across each octave's texture."""
    return float(base_frequency) * 2.0 ** np.arange(4) * PERIODS
