"""Froxel volumes: view-space grids whose W × H columns are the view rays through uv = ((x, y) + ½) / (W, H),
cut into D slices along the ray (``shaders/lib/froxel_slices.glsl``: even inside ``knee``, logarithmic
beyond, out to ``range``). Layer k of a (W, H, D + 1) volume holds what a medium gives from the camera to
slice boundary k (layer 0: the camera), and a pixel reads it trilinearly at its uv and the slice of its
distance (``froxel_read``). The volumetric fog and the light shafts march one; float64 twins here."""
from __future__ import annotations

import numpy as np

from atmos.graph import TextureDesc

KNEE_SHARE = 1.0 / 32.0      # the slices are nearly even inside range · KNEE_SHARE, logarithmic beyond
MAX_FROXELS = 256            # the most froxels along any axis


def froxel_knee(range_: float) -> float:
    """m: the knee of slices reaching ``range_`` m."""
    return float(range_) * KNEE_SHARE


def volume_desc(froxels, dtype: str = "f2") -> TextureDesc:
    """A (W, H, D + 1) RGBA storage volume for ``froxels`` = (W, H, D) slices (layer 0: the camera)."""
    w, h, d = froxels
    return TextureDesc((w, h, d + 1), components=4, dtype=dtype, storage=True)


def volume_image(frame, name: str):
    """The pass's froxel volume ``name`` as an image, its reads clamped to the edge texels (as
    :func:`froxel_lookup` reads)."""
    volume = frame.image(name)
    volume.repeat_x = volume.repeat_y = volume.repeat_z = False
    return volume


def froxel_distance(w, range_: float, knee: float):
    """Distance of slice coordinate w in [0, 1] (lib/froxel_slices.glsl)."""
    return knee * np.expm1(np.asarray(w, np.float64) * np.log1p(range_ / knee))


def froxel_w(d, range_: float, knee: float):
    """Slice coordinate in [0, 1] of distance d (lib/froxel_slices.glsl)."""
    return np.log1p(np.maximum(d, 0.0) / knee) / np.log1p(range_ / knee)


def column_rays(basis, w: int, h: int) -> tuple[np.ndarray, np.ndarray]:
    """(uv (W·H, 2), unit directions (W·H, 3)) of the columns, x fastest-varying last (index x·H + y);
    ``basis``: :func:`atmos.camera.view_basis`."""
    uv = np.stack(np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h, indexing="ij"), -1).reshape(-1, 2)
    rays = np.concatenate([uv * 2.0 - 1.0, np.ones((len(uv), 1))], 1) @ np.asarray(basis, np.float64).T
    return uv, rays / np.linalg.norm(rays, axis=-1, keepdims=True)


def froxel_lookup(volume: np.ndarray, uv, dist, range_: float, knee: float) -> np.ndarray:
    """(N, C): the trilinear read of ``volume`` (W, H, L, C) at uv (N, 2) and distance (N,) capped at
    ``range_`` (clamped to the edge texels, as the texture is): ``froxel_read`` of lib/froxel_slices.glsl."""
    w, h, layers = volume.shape[:3]
    uv = np.asarray(uv, np.float64)
    z = froxel_w(np.minimum(dist, range_), range_, knee) * (layers - 1)
    coords = [uv[:, 0] * w - 0.5, uv[:, 1] * h - 0.5, np.asarray(z, np.float64)]
    result = np.zeros((len(uv), volume.shape[3]))
    lows, fracs = [], []
    for c, n in zip(coords, (w, h, layers)):
        c = np.clip(c, 0.0, n - 1)
        lo = np.minimum(np.floor(c).astype(int), n - 2) if n > 1 else np.zeros(len(c), int)
        lows.append(lo)
        fracs.append(c - lo if n > 1 else np.zeros(len(c)))
    for corner in range(8):
        bits = [(corner >> i) & 1 for i in range(3)]
        weight = np.ones(len(uv))
        index = []
        for bit, lo, frac, n in zip(bits, lows, fracs, (w, h, layers)):
            weight = weight * (frac if bit else 1.0 - frac)
            index.append(np.minimum(lo + bit, n - 1))
        result += weight[:, None] * volume[index[0], index[1], index[2]]
    return result
