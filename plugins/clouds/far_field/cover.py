"""The far field's cover follows the simulation's.

On the GPU (``clouds/far_field/cover.comp``), each frame: the edge-weighted fraction of the volume's
columns that are covered (summed density of mix(A, B, t) above ``CloudSettings.cover_threshold``),
``cover = Σ w·[sum > threshold] / Σ w`` with ``w`` the edge weight (:mod:`atmos.plugins.clouds.volume.edge`)
at the column's centre; :func:`.reference.volume_cover` is it in float64; and how often the cover
changes from one column to the next (:func:`.reference.volume_transitions`), which sizes the far
field's tile (:func:`matched_tile_size`: its cover then changes along a line as often per metre). The far-field shader ranks each
point's fbm among the layer's (the quantile table :func:`level_table` makes once per texture setting,
baked by :func:`rank_table` into a texture of the rank as a function of fbm and level: one filtered fetch)
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

from atmos.plugins.clouds.far_field.pattern import PERIODS, octave_frequencies, octave_uv
from atmos.tile_octaves import OCTAVES, WEIGHTS, octave_key, tile_noise

QUANTILES = 33          # table entries: quantiles at 0, 1/32, ..., 1
GRID = 256              # most texels per side of the octave textures the table is measured on
LEVELS = 8              # table rows: mip levels 0..7 of the table's grid (field.glsl FIELD_LEVELS)
SPAN = 40.0             # tiles per side of the world square the quantiles are measured over
SAMPLES = 384           # samples per side of it (the octaves' phases are unrelated there: their joint spread)
LINES, LINE_TILES, LINE_STEP = 48, 8.0, 1.0 / 256.0     # the crossing rate: lines along x and z, tiles, spacing
RANK_COLUMNS = 2048     # rank table texels per level (field.glsl far_rank_table): reference.rank_table_error


def mip_chain(texture: np.ndarray) -> list:
    """[level 0, 1, ...] of a square periodic texture (2×2 means, as build_mipmaps), down to 1×1."""
    levels = [texture]
    while levels[-1].shape[0] > 1:
        t = levels[-1]
        levels.append(0.25 * (t[0::2, 0::2] + t[1::2, 0::2] + t[0::2, 1::2] + t[1::2, 1::2]))
    return levels


def sample(texture: np.ndarray, uv: np.ndarray, weight_bits: int | None = None) -> np.ndarray:
    """Bilinear with repeat, texel i centred at (i + 0.5)/n (texture(), one level); ``weight_bits``: a
    model of a texture unit's filter (float32 coordinates, sub-texel weights rounded to that many bits:
    8 on a machine with an NVIDIA GPU), None: exact (a texture unit that filters in float)."""
    n = texture.shape[0]
    if weight_bits is None:
        p = uv * n - 0.5
    else:
        p = (np.asarray(uv, np.float32) * np.float32(n) - np.float32(0.5)).astype(np.float64)
    i0 = np.floor(p).astype(np.int64)
    f = p - i0
    if weight_bits is not None:
        f = np.round(f * 2.0 ** int(weight_bits)) / 2.0 ** int(weight_bits)
    at = lambda di, dk: texture[(i0[..., 0] + di) % n, (i0[..., 1] + dk) % n]
    return ((1 - f[..., 0]) * (1 - f[..., 1]) * at(0, 0) + f[..., 0] * (1 - f[..., 1]) * at(1, 0)
            + (1 - f[..., 0]) * f[..., 1] * at(0, 1) + f[..., 0] * f[..., 1] * at(1, 1))


def pattern_fbm(chains, xz_tiles: np.ndarray, level: float) -> np.ndarray:
    """The drawn fbm at world points ``xz_tiles`` (..., 2) in tiles (no drift), table level ``level``:
    octave k read at its own level level − log2(PERIODS[k]) (field.glsl field_fbm), trilinear."""
    uv = octave_uv(xz_tiles, np.zeros((4, 2)), 1.0)
    fbm = np.zeros(xz_tiles.shape[:-1])
    for k, (w, chain) in enumerate(zip(WEIGHTS, chains)):
        lk = float(np.clip(level - np.log2(PERIODS[k]), 0.0, len(chain) - 1))
        l0 = min(int(lk), len(chain) - 2) if len(chain) > 1 else 0
        t = lk - l0
        v = sample(chain[l0], uv[k])
        if t > 0.0:
            v = (1.0 - t) * v + t * sample(chain[l0 + 1], uv[k])
        fbm += w * v
    return fbm


@lru_cache(maxsize=8)
def _measure(base_frequency: int, seed: int, size: int) -> tuple:
    grid = min(int(size), GRID)
    i = (np.arange(grid) + 0.5) / grid
    uv = np.stack(np.meshgrid(i, i, indexing="ij"), -1)
    chains = [mip_chain(tile_noise(uv, f, octave_key(seed, k)))
              for k, f in zip(range(OCTAVES), octave_frequencies(base_frequency))]
    g = (np.arange(SAMPLES) + 0.5) * SPAN / SAMPLES
    points = np.stack(np.meshgrid(g, g, indexing="ij"), -1)
    rows = np.array([np.quantile(pattern_fbm(chains, points, m), np.linspace(0.0, 1.0, QUANTILES)) for m in range(LEVELS)])
    t = np.arange(0.0, LINE_TILES, LINE_STEP)
    across = (np.arange(LINES) + 0.5) * SPAN / LINES
    lines = [np.stack(np.broadcast_arrays(t[None, :] + 0.37 * a, np.full((1, len(t)), a)[..., None][..., 0]), -1)
             for a in across]
    along = np.concatenate([np.stack([l, l[..., ::-1]]) for l in lines])          # lines along x and along z
    line_fbm = pattern_fbm(chains, along, 0.0)
    crossings = np.array([(np.diff(line_fbm > q, axis=-1)).mean() / LINE_STEP for q in rows[0]])
    return rows, float(np.log2(size / grid)), crossings


def level_table(base_frequency: int, seed: int, size: int = GRID) -> tuple:
    """(quantiles (LEVELS, QUANTILES), first level) of the fbm the far field draws (:mod:`.pattern`: each
    octave turned and repeating at its own period) for octave textures of ``size`` texels, measured over a
    SPAN-tile square where the octaves' phases are unrelated: row m holds the quantiles of the pattern with
    each octave's ``min(size, GRID)`` texels box-filtered to level m − log2(PERIODS[k]) (the mip chain,
    trilinear), and ``first`` = log2(size / grid): texture mip level L reads row L − first (clamped)."""
    rows, first, _ = _measure(int(base_frequency), int(seed), int(size))
    return rows, first


def rank_table(quantiles, columns: int = RANK_COLUMNS) -> tuple:
    """(table (levels, columns), span) of field.glsl's far_rank_table: row m holds the rank of level m
    (linear between its ``quantiles`` row, 0 below, 1 above) at ``columns`` fbm values evenly spanning
    all rows' quantiles, one per texel centre; span = (fbm at the texture's left edge, texture widths per
    unit fbm), so the texture x of fbm f is (f - span[0]) * span[1]. Between two columns the texture's
    linear filter is the rank itself except in the cells holding a quantile (reference.rank_table_error)."""
    q = np.asarray(quantiles, np.float64)
    lo, hi = float(q[:, 0].min()), float(q[:, -1].max())
    hi = max(hi, lo + 1e-9)
    f = np.linspace(lo, hi, int(columns))
    ranks = np.linspace(0.0, 1.0, q.shape[1])
    table = np.array([np.interp(f, row, ranks) for row in q])
    scale = (int(columns) - 1) / (int(columns) * (hi - lo))
    return table, (lo - 0.5 / (int(columns) * scale), scale)


@lru_cache(maxsize=8)
def level_ranks(base_frequency: int, seed: int, size: int = GRID) -> tuple:
    """(table, span, first level): :func:`rank_table` of :func:`level_table`'s rows, what the far field
    binds once per texture setting."""
    rows, first = level_table(base_frequency, seed, size)
    table, span = rank_table(rows)
    return table, span, first


def pattern_crossings(base_frequency: int, seed: int, size: int = GRID) -> np.ndarray:
    """(QUANTILES,) how often per tile a straight line (along x or z) crosses the sharp pattern's
    quantile k, i.e. the edge of the cover 1 − k/32: what the far field's tile is sized by to have
    the volume's cover transitions per metre (:func:`matched_tile_size`)."""
    return _measure(int(base_frequency), int(seed), int(size))[2]


def matched_tile_size(crossings, cover: float, volume_rate: float) -> float | None:
    """The tile (m) at which the far field's cover ``cover`` changes along a line as often as the
    volume's, ``volume_rate`` transitions per metre (cover.comp): the pattern's crossings per tile at
    its quantile 1 − cover over the volume's per metre; None without a measurable volume (no
    transitions, or cover 0 or 1)."""
    if not (volume_rate > 0.0 and 0.0 < cover < 1.0):
        return None
    per_tile = float(np.interp(1.0 - cover, np.linspace(0.0, 1.0, len(crossings)), crossings))
    return per_tile / volume_rate if per_tile > 0.0 else None


def fbm_quantiles(base_frequency: int, seed: int, size: int) -> tuple:
    """(QUANTILES,) fbm values q_k with the fraction k/(QUANTILES − 1) of the layer's sharp fbm (mip 0)
    at or below q_k: row 0 of the table the shader gets for octave textures of ``size`` texels (measured
    on the texels, so a 64-texel layer's table differs from a 256-texel one's)."""
    return tuple(float(v) for v in level_table(base_frequency, seed, size)[0][0])
