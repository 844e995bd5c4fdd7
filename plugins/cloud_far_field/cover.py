"""The far field's cover follows the simulation's.

On the GPU (``cloud_far_field/cover.comp``), each frame: the edge-weighted fraction of the volume's
columns that are covered (summed density of mix(A, B, t) above ``CloudSettings.cover_threshold``),
``cover = Σ w·[sum > threshold] / Σ w`` with ``w`` the edge weight (:mod:`atmos.plugins.clouds.edge`)
at the column's centre; :func:`.reference.volume_cover` is it in float64. The far-field shader turns it into
the fbm threshold that leaves that fraction of its layer clear of cloud: the (1 − cover) quantile of
the layer's fbm, interpolated in the table :func:`fbm_quantiles` makes once per texture setting.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from atmos.plugins.sky_layer.octaves import OCTAVES, WEIGHTS, octave_key, tile_noise

QUANTILES = 33          # table entries: quantiles at 0, 1/32, ..., 1
GRID = 64               # samples per side of the tile the table is measured on


@lru_cache(maxsize=8)
def fbm_quantiles(base_frequency: int, seed: int) -> tuple:
    """(QUANTILES,) fbm values q_k with the fraction k/(QUANTILES − 1) of the layer's fbm at or below q_k."""
    i = (np.arange(GRID) + 0.5) / GRID
    uv = np.stack(np.meshgrid(i, i, indexing="ij"), -1)
    fbm = sum(w * tile_noise(uv, base_frequency * 2 ** k, octave_key(seed, k)) for k, w in zip(range(OCTAVES), WEIGHTS))
    return tuple(float(v) for v in np.quantile(fbm, np.linspace(0.0, 1.0, QUANTILES)))


def emptiness(quantiles, cover: float) -> float:
    """The fbm threshold above which the fraction ``cover`` of the layer lies (``far.frag``'s lookup)."""
    q = np.asarray(quantiles, np.float64)
    x = (1.0 - float(np.clip(cover, 0.0, 1.0))) * (len(q) - 1)
    k = min(int(x), len(q) - 2)
    return float(q[k] + (q[k + 1] - q[k]) * (x - k))
