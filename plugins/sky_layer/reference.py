"""numpy float64 references of the cloud layer: tiling octaves, fbm, remap and shading."""
from __future__ import annotations

import numpy as np

from atmos.tile_octaves import WEIGHTS, light_shift, octave_key, tile_noise  # noqa: F401  (the GPU side's own)

RAY = np.array([0.0, 0.2, 0.4, 0.6])


def octave_texture(size: int, frequency: float, k, light_shift, steps=(0, 1, 2, 3)) -> np.ndarray:
    """(size, size, 4) indexed [x, y, channel]: channel c sampled at texel/size + steps[c]·light_shift."""
    i = np.arange(size) / size
    uv = np.stack(np.meshgrid(i, i, indexing="ij"), axis=-1)
    shift = np.asarray(light_shift, np.float64)
    return np.stack([tile_noise(uv + c * shift, frequency, k) for c in np.asarray(steps, np.float64)], axis=-1)


def fbm(samples) -> np.ndarray:
    """Σ_k w_k n_k with w = 1/2, 1/4, 1/8, 1/16; samples (4 octaves, ..., 4 channels)."""
    return np.tensordot(WEIGHTS, np.asarray(samples, np.float64), axes=1)


def remap(fbm_value, emptiness: float, sharpness: float) -> np.ndarray:
    """(clamp(f, emptiness, sharpness) − emptiness) / (sharpness − emptiness), in [0, 1]."""
    f = np.asarray(fbm_value, np.float64)
    return (np.clip(f, emptiness, sharpness) - emptiness) / (sharpness - emptiness)


def shade(fbm_rgba, params, light, fade=1.0) -> np.ndarray:
    """Premultiplied (rgb·α, α) of fbm samples (..., 4), as ``sky_layer_shade`` in GLSL (α: coverage)."""
    d = remap(fbm_rgba, params.emptiness, params.sharpness)
    amount = (np.maximum(d - RAY, 0.0) * 0.25).sum(-1)
    alpha = np.clip(params.thickness * amount, 0.0, 1.0) * np.asarray(fade, np.float64)
    lit, color = np.asarray(params.lit_color), np.asarray(params.color)
    rgb = (lit + (color - lit) * amount[..., None]) * np.asarray(light, np.float64)
    return np.concatenate([rgb * alpha[..., None], alpha[..., None]], axis=-1)
