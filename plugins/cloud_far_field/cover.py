"""The far field's cover follows the simulation's.

On the GPU (``cloud_far_field/cover.comp``), each frame: the edge-weighted fraction of the volume's
columns that are covered (summed density of mix(A, B, t) above ``CloudSettings.cover_threshold``),
``cover = Σ w·[sum > threshold] / Σ w`` with ``w`` the edge weight (:mod:`atmos.plugins.clouds.edge`)
at the column's centre; :func:`.reference.volume_cover` is it in float64. The far-field shader ranks each
point's fbm among the layer's (the quantile table :func:`level_table` makes once per texture setting)
and takes the volume's column sum at that rank, so the same fraction of its layer is clouded.

Per detail level: far away the shader samples blurred mip levels of the octaves, whose fbm has a
narrower spread round the same mean, so one threshold from the sharp pattern would let a blurred
pattern clear it everywhere (cover > 0.5: a white overcast band at the horizon) or nowhere.
:func:`level_table` gives each mip level its own quantiles (of the pattern box-filtered as the mip
chain is), so a point's rank in its level (field.glsl far_field_rank) is clouded over the same
fraction with the same distribution of column sums (far_quantile) at every level.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from atmos.plugins.sky_layer.octaves import OCTAVES, WEIGHTS, octave_key, tile_noise

QUANTILES = 33          # table entries: quantiles at 0, 1/32, ..., 1
GRID = 256              # most samples per side of the tile the table is measured on
LEVELS = 8              # table rows: mip levels 0..7 of the table's grid (field.glsl FIELD_LEVELS)


@lru_cache(maxsize=8)
def level_table(base_frequency: int, seed: int, size: int = GRID) -> tuple:
    """(quantiles (LEVELS, QUANTILES), first level) for octave textures of ``size`` texels: row m
    holds the quantiles of the fbm on a ``min(size, GRID)`` grid box-filtered m times (2×2 means, as
    the mip chain), and ``first`` = log2(size / grid): texture mip level L reads row L − first (clamped; rows past the
    2×2 level repeat it)."""
    grid = min(int(size), GRID)
    i = (np.arange(grid) + 0.5) / grid
    uv = np.stack(np.meshgrid(i, i, indexing="ij"), -1)
    fbm = sum(w * tile_noise(uv, base_frequency * 2 ** k, octave_key(seed, k)) for k, w in zip(range(OCTAVES), WEIGHTS))
    rows = []
    while len(rows) < LEVELS:
        rows.append(np.quantile(fbm, np.linspace(0.0, 1.0, QUANTILES)))
        if fbm.shape[0] > 2:
            fbm = 0.25 * (fbm[0::2, 0::2] + fbm[1::2, 0::2] + fbm[0::2, 1::2] + fbm[1::2, 1::2])
    return np.array(rows), float(np.log2(size / grid))


def fbm_quantiles(base_frequency: int, seed: int, size: int) -> tuple:
    """(QUANTILES,) fbm values q_k with the fraction k/(QUANTILES − 1) of the layer's sharp fbm (mip 0)
    at or below q_k: row 0 of the table the shader gets for octave textures of ``size`` texels (measured
    on the texels, so a 64-texel layer's table differs from a 256-texel one's)."""
    return tuple(float(v) for v in level_table(base_frequency, seed, size)[0][0])
