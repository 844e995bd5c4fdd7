"""numpy float64 references of the light shafts: the screen mode's occlusion mask and radial blur
toward the sun, and the march mode's in-scattering along the view rays (:func:`march_shafts`), or
through a froxel volume (:func:`froxel_shafts`, :func:`froxel_apply`).

Images are (h, w, c) in GL row order (row 0 at the bottom), pixel (x, y) at uv ((x+0.5)/w, (y+0.5)/h).
"""
from __future__ import annotations

import numpy as np

from atmos.blue_noise import blue_noise
from atmos.froxels import column_rays, froxel_distance, froxel_knee, froxel_lookup
from atmos.plugins.clouds.shadows import reference as shadows_reference
from atmos.plugins.light_shafts.settings import blur_scale
from atmos.render_core import HDR_MAX

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
    tap i weighing ``weight·decay^(i−1)``, summed and scaled by ``exposure·strength``, at most
    :data:`~atmos.render_core.HDR_MAX`."""
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
            out[..., ch] += shadows_reference.zero_border_bilinear(mask[..., ch], p) * falloff
        falloff *= settings.decay
    return np.minimum(out * blur_scale(settings, strength), HDR_MAX)


def march_jitter(w: int, h: int) -> np.ndarray:
    """(h, w) start offsets in [0, 1) of the marched shafts' low-res texels (shaders/light_shafts/march.comp):
    the blue-noise tile (atmos.blue_noise), row 0 at the bottom."""
    tile = blue_noise().astype(np.float64)
    return np.tile(tile, (-(-h // tile.shape[0]), -(-w // tile.shape[1])))[:h, :w]


def march_shafts(low_depth, basis, camera_pos, near: float, far: float, frame_size, factor: int, sun_dir,
                 irradiance, settings, optical_depth=None) -> np.ndarray:
    """(h, w, 4) (in-scattered light, transmittance) of the marched shafts at the low-res texels of
    ``low_depth`` (window depth, row 0 at the bottom): ``settings.steps`` samples at ``(i + jitter)·ds``
    along each texel's view ray (through its block's centre; ``basis``: :func:`atmos.camera.view_basis`)
    to its depth or ``max_distance``, ``L = Σ σ p(cos) E exp(−τ_sun − σ s_i) ds`` (at most ``HDR_MAX``),
    ``T = exp(−σ d)``;
    ``optical_depth(points (..., 3)) -> (...)`` the sun's optical depth through the clouds (None: 0),
    e.g. :func:`atmos.plugins.clouds.shadows.reference.sun_optical_depth` bound to a volume."""
    depth = np.asarray(low_depth, np.float64)
    h, w = depth.shape
    x, y = np.meshgrid(np.arange(w), np.arange(h))
    uv = np.stack([(x + 0.5) * factor / frame_size[0], (y + 0.5) * factor / frame_size[1]], -1)
    ray = np.concatenate([uv * 2.0 - 1.0, np.ones((h, w, 1))], -1) @ np.asarray(basis, np.float64).T
    length = np.linalg.norm(ray, axis=-1)
    direction = ray / length[..., None]
    view_z = near / ((1.0 - depth) + depth * (near / far))
    d = np.minimum(np.where(depth >= 1.0, settings.max_distance, view_z * length), settings.max_distance)
    ds = d / settings.steps
    sigma, j = settings.scattering, march_jitter(w, h)
    total = np.zeros((h, w))
    for i in range(settings.steps):
        s = (i + j) * ds
        tau = 0.0 if optical_depth is None else optical_depth(np.asarray(camera_pos, np.float64) + direction * s[..., None])
        total += np.exp(-tau - sigma * s)
    p = settings.phase(direction @ np.asarray(sun_dir, np.float64))
    light = np.minimum(np.asarray(irradiance, np.float64) * (sigma * p * total * ds)[..., None], HDR_MAX)
    return np.concatenate([light, np.exp(-sigma * d)[..., None]], -1)


def froxel_shafts(camera_pos, basis, froxels, sun_dir, irradiance, settings, optical_depth=None,
                  jitter: float = 0.5) -> np.ndarray:
    """(W, H, D + 1, 4) float64: shaders/light_shafts/froxels.comp without a fog or the aerial perspective —
    each column's view ray (:func:`atmos.froxels.column_rays`) sampled once per slice at s, the share
    ``jitter`` of its depth (0.5: the middle),
    layer k holding (Σ σ p(cos) E exp(−τ_sun − σ s) ds, exp(−σ d_k)) from the camera to slice boundary
    d_k; ``optical_depth`` as for :func:`march_shafts`."""
    w, h, d = froxels
    _, dirs = column_rays(basis, w, h)
    bounds = froxel_distance(np.arange(d + 1) / d, settings.max_distance, froxel_knee(settings.max_distance))
    sigma = settings.scattering
    lit = np.asarray(irradiance, np.float64) * (sigma * settings.phase(dirs @ np.asarray(sun_dir, np.float64)))[:, None]
    out = np.zeros((len(dirs), d + 1, 4))
    out[:, 0, 3] = 1.0
    light = np.zeros((len(dirs), 3))
    for k in range(1, d + 1):
        s, ds = bounds[k - 1] + jitter * (bounds[k] - bounds[k - 1]), bounds[k] - bounds[k - 1]
        tau = 0.0 if optical_depth is None else optical_depth(np.asarray(camera_pos, np.float64) + dirs * s)
        light = light + lit * (np.exp(-tau - sigma * s) * ds)[:, None]
        out[:, k, :3], out[:, k, 3] = light, np.exp(-sigma * bounds[k])
    return out.reshape(w, h, d + 1, 4)


def froxel_apply(volume, color, depth, basis, near: float, far: float, settings) -> np.ndarray:
    """(h, w, 3): shaders/light_shafts/froxel_apply.comp without a fog or the aerial perspective — each
    pixel of ``color`` (h, w, 3) and window ``depth`` (h, w) (row 0 at the bottom) reads ``volume`` at its
    distance (the sky: ``max_distance``): min(L, HDR_MAX) + T · color."""
    depth = np.asarray(depth, np.float64)
    h, w = depth.shape
    uv = pixel_uv(w, h).reshape(-1, 2)
    ray = np.concatenate([uv * 2.0 - 1.0, np.ones((len(uv), 1))], 1) @ np.asarray(basis, np.float64).T
    z = depth.reshape(-1)
    view_z = near / ((1.0 - z) + z * (near / far))
    dist = np.where(z >= 1.0, settings.max_distance, view_z * np.linalg.norm(ray, axis=-1))
    knee = froxel_knee(settings.max_distance)
    sums = froxel_lookup(np.asarray(volume, np.float64), uv, dist, settings.max_distance, knee).reshape(h, w, 4)
    return np.minimum(sums[..., :3], HDR_MAX) + sums[..., 3:] * np.asarray(color, np.float64)[..., :3]
