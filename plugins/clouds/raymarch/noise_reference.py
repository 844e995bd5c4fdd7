"""float64 reference of the detail noise (``shaders/clouds/raymarch/noise.comp``) and of the erosion
``detail_density`` (``shaders/clouds/raymarch/detail.glsl``); used by the tests, never by the renderer.

The noise, per texture of ``size``^3 texels (texel j sits at tile coordinate u = (j + 0.5) / size):

* Worley W_f(u) = 1 - clamp(F1, 0, 1): F1 the distance (in cells) from q = u·f to the nearest feature
  point of a periodic f^3 lattice, one point per cell at a hashed position (three 10-bit fields of one
  :func:`atmos.hashing.hash_counter`), searched in the 3^3 cells around q; bright at the points.
* Worley FBM at frequency f: 0.625·W_f + 0.25·W_2f + 0.125·W_4f (each octave its own key).
* Perlin FBM at f: (4 n_f + 2 n_2f + n_4f) / 7 of the periodic gradient noise n of
  ``atmos/gradient_noise.py`` (the same lattice hash), mapped to [0, 1] by clamp(0.5 + 0.5·GAIN·fbm).
* Perlin–Worley PW = remap(P, -W, 1, 0, 1) = (P + W) / (1 + W), in [0, 1] for P, W in [0, 1], with W
  the Worley FBM of the same frequency (channel G): Nubis' remap(perlin, worley - 1, 1, 0, 1) written
  with our bright-at-the-points W = 1 - F1 (theirs is the distance-like 1 - W): the Perlin billows
  dilated by the Worley cells.

Each stored channel is contrast-stretched, clamp((v - lo) / (hi - lo), 0, 1) with ``PW_RANGE`` for
Perlin–Worley and ``WORLEY_RANGE`` for the Worley FBMs (about the 0.5 % and 99.5 % points), so it
spans [0, 1].

With power-of-two sizes and frequencies q is exact in binary floating point, so every value at texel
j + size equals the one at texel j bit for bit (the textures tile without a seam).
"""
from __future__ import annotations

import numpy as np

from atmos.hashing import hash_counter, stream_key
from atmos.plugins.clouds.raymarch.noise import (BAND_STRENGTH, BASE_LAYOUT, COVERAGE, DETAIL_LAYOUT, DETAIL_RATIO, NOISE_RULE,
                                                PERLIN_GAIN, PW_RANGE, WORLEY_RANGE, band_width, detail_fade,
                                                detail_offsets)
from atmos.gradient_noise import periodic_noise, sample_repeat_trilinear

WORLEY_WEIGHTS = (0.625, 0.25, 0.125)
PERLIN_WEIGHTS = (4 / 7, 2 / 7, 1 / 7)
OFFSETS = np.array(list(np.ndindex(3, 3, 3)), np.int64) - 1       # the 27 cells around a point


def noise_key(seed: int, texture: int, perlin: bool, channel: int, octave: int) -> tuple[int, int]:
    """(ka, kb) of one noise layer: plane = texture·64 + perlin·32 + channel·4 + octave."""
    ka, kb = stream_key(seed, 0, NOISE_RULE, texture * 64 + perlin * 32 + channel * 4 + octave)
    return int(ka), int(kb)


def worley(q, period: int, key) -> np.ndarray:
    """1 - clamp(F1, 0, 1) at lattice coordinates ``q`` (..., 3) of a ``period``-periodic lattice."""
    q = np.asarray(q, np.float64)
    cell = np.floor(q).astype(np.int64)
    best = np.full(q.shape[:-1], np.inf)
    for o in OFFSETS:
        n = cell + o
        w = n % period
        h = hash_counter(w[..., 0] + period * (w[..., 1] + period * w[..., 2]), *key).astype(np.int64)
        jitter = np.stack([h & 1023, (h >> 10) & 1023, (h >> 20) & 1023], -1) + 0.5
        best = np.minimum(best, np.linalg.norm(q - (n + jitter / 1024.0), axis=-1))
    return 1.0 - np.clip(best, 0.0, 1.0)


def worley_fbm(u, frequency: int, seed: int, texture: int, channel: int) -> np.ndarray:
    """The Worley FBM of one channel at tile coordinates ``u`` (..., 3)."""
    return sum(w * worley(u * (frequency << k), frequency << k, noise_key(seed, texture, False, channel, k))
               for k, w in enumerate(WORLEY_WEIGHTS))


def perlin_fbm(u, frequency: int, seed: int, texture: int) -> np.ndarray:
    """Perlin FBM mapped to [0, 1]."""
    fbm = sum(w * periodic_noise(u * (frequency << k), frequency << k, noise_key(seed, texture, True, 0, k))
              for k, w in enumerate(PERLIN_WEIGHTS))
    return np.clip(0.5 + 0.5 * PERLIN_GAIN * fbm, 0.0, 1.0)


def perlin_worley(p, w) -> np.ndarray:
    """remap(p, -w, 1, 0, 1) = (p + w) / (1 + w)."""
    return np.clip((p + w) / (1.0 + w), 0.0, 1.0)


def texels(index, size: int, layout, seed: int) -> np.ndarray:
    """(..., 4) values at integer texel indices ``index`` (..., 3) (any integers: they wrap) of a
    texture laid out as ``layout`` (:data:`BASE_LAYOUT` or :data:`DETAIL_LAYOUT`)."""
    texture, perlin_frequency, worley_frequencies = layout
    u = (np.asarray(index, np.float64) + 0.5) / size
    w = [worley_fbm(u, f, seed, texture, c) for c, f in enumerate(worley_frequencies)]
    ws = [stretch(v, WORLEY_RANGE) for v in w]
    if perlin_frequency:
        pw = perlin_worley(perlin_fbm(u, perlin_frequency, seed, texture), w[0])
        return np.stack([stretch(pw, PW_RANGE), *ws], -1)
    return np.stack([*ws, np.ones_like(w[0])], -1)


def stretch(v, value_range) -> np.ndarray:
    lo, hi = value_range
    return np.clip((v - lo) / (hi - lo), 0.0, 1.0)


def volume(size: int, layout, seed: int) -> np.ndarray:
    """The whole texture, (size, size, size, 4) indexed [x, y, z, channel]."""
    j = np.arange(size)
    return texels(np.stack(np.meshgrid(j, j, j, indexing="ij"), -1), size, layout, seed)


def base_volume(size: int, seed: int) -> np.ndarray:
    return volume(size, BASE_LAYOUT, seed)


def detail_volume(size: int, seed: int) -> np.ndarray:
    return volume(size, DETAIL_LAYOUT, seed)


def erode(x, e) -> np.ndarray:
    """remap(x, e, 1, 0, 1) clamped, e at most 0.98 (so x = 1 stays 1)."""
    e = np.minimum(e, 0.98)
    return np.clip((x - e) / (1.0 - e), 0.0, 1.0)


def detail_density(d, p, base, detail, octaves: int, scale: float, strength: float,
                   time: float = 0.0, wind=(0.0, 0.0, 0.0), layer=(0.0, 1.0), footprint=0.0) -> np.ndarray:
    """What ``detail_density(d, p)`` returns for densities ``d`` (...) at world points ``p`` (..., 3) m,
    with ``base`` and ``detail`` the textures as [x, y, z, channel] arrays in [0, 1] (as read back) and
    ``layer`` the layer's (base y, height) in m, ``scale`` the base tile in m: 0 octaves d itself, else
    clamp(d, 0, 1) grown and carved by the shape noise and eroded by the detail noise as
    ``detail.glsl`` describes, each band's strength scaled by :func:`detail_fade` of ``footprint``
    (the pixel's width in m at each point, (...) or a number)."""
    if octaves == 0:
        return np.asarray(d, np.float64)
    x = np.clip(np.nan_to_num(np.asarray(d, np.float64)), 0.0, 1.0)
    out = x / COVERAGE
    off_base, off_fine = detail_offsets(time, wind, scale)
    p = np.asarray(p, np.float64)
    h = np.clip((p[..., 1] - layer[0]) / layer[1], 0.0, 1.0)
    u = p / scale - off_base
    n = np.stack([sample_repeat_trilinear(base[..., c], u) for c in range(4)], -1)
    shape = n[..., 0]
    if octaves >= 2:
        fbm = n[..., 1:] @ np.array(WORLEY_WEIGHTS)
        shape = np.clip((shape + 1.0 - fbm) / (2.0 - fbm), 0.0, 1.0)
    keep = detail_fade(footprint, scale)
    w = 1.0 - (1.0 - band_width(strength)) * keep   # the shape band: a threshold e and a sharp remap (the dilation)
    out = np.clip((out - np.minimum(keep * strength * (1.0 - shape) * (0.45 + 0.55 * h), 1.0 - w)) / w, 0.0, 1.0)
    if octaves >= 3:
        v = p * (DETAIL_RATIO / scale) - off_fine
        fine = sum(w * sample_repeat_trilinear(detail[..., c], v) for c, w in enumerate(WORLEY_WEIGHTS))
        keep_fine = detail_fade(footprint, scale / DETAIL_RATIO)
        out = erode(out, out * keep_fine * BAND_STRENGTH * strength * (fine + (1.0 - 2.0 * fine) * np.clip(3.0 * h, 0.0, 1.0)))
    return np.where(x >= COVERAGE, x, COVERAGE * out)
