"""numpy float64 references of the light shafts: the occlusion mask and the radial blur toward the sun.

Images are (h, w, c) in GL row order (row 0 at the bottom), pixel (x, y) at uv ((x+0.5)/w, (y+0.5)/h).
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.cloud_shadows.reference import zero_border_bilinear

LUMA = np.array([0.2126, 0.7152, 0.0722])


def pixel_uv(w: int, h: int) -> np.ndarray:
    """(h, w, 2) uv of the pixel centres."""
    x, y = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    return np.stack([x, y], axis=-1)


def occlusion_mask(color, depth, sun_uv, settings) -> np.ndarray:
    """(h, w, 3): the sky (depth >= 1) brighter than ``threshold``, by its excess luminance (at most
    ``ceiling``) times how open to the sky it is, ``1 − clip(color.a, 0, 1)`` (``color.a``: the sky
    occlusion of :mod:`atmos.render_core`), near the sun. ``color``: (h, w, 4) RGBA."""
    color = np.asarray(color, np.float64)
    if color.ndim != 3 or color.shape[-1] != 4:
        raise ValueError(f"occlusion_mask needs (h, w, 4) RGBA colour (alpha: sky occlusion), got shape {color.shape}")
    c = np.maximum(color[..., :3], 0.0)
    h, w = c.shape[:2]
    lum = c @ LUMA
    excess = np.clip(lum - settings.threshold, 0.0, settings.ceiling) * (1.0 - np.clip(color[..., 3], 0.0, 1.0))
    bright = c * (excess / np.maximum(lum, 1e-4))[..., None]
    r = np.linalg.norm((pixel_uv(w, h) - np.asarray(sun_uv)) * np.array([w / h, 1.0]), axis=-1)
    near = np.exp(-(r / settings.radius) ** 2)
    return np.where((np.asarray(depth) >= 1.0)[..., None], bright * near[..., None], 0.0)


def radial_blur(mask, sun_uv, settings, strength: float = 1.0) -> np.ndarray:
    """(h, w, c): per pixel, ``samples`` bilinear taps (zero outside the mask) stepping toward the sun,
    tap i weighing ``weight·decay^(i−1)``, summed and scaled by ``exposure·strength``."""
    mask = np.asarray(mask, np.float64)
    h, w, channels = mask.shape
    uv = pixel_uv(w, h)
    step = (uv - np.asarray(sun_uv)) * (settings.density / settings.samples)
    out = np.zeros_like(mask)
    falloff = 1.0
    for i in range(1, settings.samples + 1):
        texel = (uv - i * step) * np.array([w, h]) - 0.5          # (h, w, 2) as (x, y)
        p = texel[..., ::-1]                                        # index order of mask: (row, column)
        for ch in range(channels):
            out[..., ch] += zero_border_bilinear(mask[..., ch], p) * (settings.weight * falloff)
        falloff *= settings.decay
    return out * (settings.exposure * strength)
