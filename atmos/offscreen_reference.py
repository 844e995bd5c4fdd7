"""numpy float64 references of the off-screen clouds' depth and composite draws (:mod:`.offscreen`).

Images are (h, w, ...) in GL row order (row 0 at the bottom). The sprites drawn off screen fade against
:func:`far_depth` (:func:`atmos.plugins.clouds.sprites.reference.soft_fade`).
"""
from __future__ import annotations

import numpy as np

from atmos.offscreen import EDGE, low_size


def far_depth(depth: np.ndarray, factor: int) -> np.ndarray:
    """The low-res depth: the largest ``depth`` in each factor × factor block (blocks cut at the edge)."""
    h, w = depth.shape
    lw, lh = low_size((w, h), factor)
    padded = np.full((lh * factor, lw * factor), -np.inf)
    padded[:h, :w] = depth
    return padded.reshape(lh, factor, lw, factor).max(axis=(1, 3))


def upsample_weights(low_depth: np.ndarray, px: np.ndarray, py: np.ndarray, pixel_inv: np.ndarray,
                     near: float, far: float, edge: float = EDGE):
    """``lib/upsample.glsl``: the four low-res texels around (px, py) (texel centres at
    integers, clamped) as [(qx, qy, weight)], bilinear unless one's view depth differs from the
    pixel's (``pixel_inv`` = 1 / view depth) by more than ``edge`` (relative); then weight 1 on the
    texel nearest in depth (the first of equals, in the order (0,0), (1,0), (0,1), (1,1))."""
    lh, lw = low_depth.shape
    x0, y0 = np.floor(px).astype(int), np.floor(py).astype(int)
    fx, fy = px - x0, py - y0
    taps, best = [], np.full(px.shape, np.inf)
    nearest = np.zeros(px.shape, int)
    is_edge = np.zeros(px.shape, bool)
    for k, (ox, oy) in enumerate(((0, 0), (1, 0), (0, 1), (1, 1))):
        qx, qy = np.clip(x0 + ox, 0, lw - 1), np.clip(y0 + oy, 0, lh - 1)
        wq = inv_depth(low_depth[qy, qx].astype(np.float64), near, far)
        rel = np.abs(pixel_inv - wq) / np.maximum(np.minimum(pixel_inv, wq), 1e-30)
        is_edge |= rel > edge
        nearest = np.where(rel < best, k, nearest)
        best = np.minimum(rel, best)
        taps.append((qx, qy, (fx if ox else 1 - fx) * (fy if oy else 1 - fy)))
    return [(qx, qy, np.where(is_edge, (nearest == k).astype(float), weight)) for k, (qx, qy, weight) in enumerate(taps)]


def inv_depth(window_depth, near: float, far: float):
    """1 / view depth, linear in window depth."""
    return (1.0 - window_depth) / near + window_depth / far


def composite(clouds: np.ndarray, cloud_depth: np.ndarray, scene_depth: np.ndarray, factor: int,
              near: float, far: float, edge: float = EDGE) -> np.ndarray:
    """(h, w, 4) premultiplied clouds at full resolution, depth-aware (:func:`upsample_weights`), the
    low-res texels at the blocks' centres."""
    h, w = scene_depth.shape
    ys, xs = np.mgrid[0:h, 0:w]
    px, py = (xs + 0.5) / factor - 0.5, (ys + 0.5) / factor - 0.5
    wp = inv_depth(scene_depth.astype(np.float64), near, far)
    return sum(weight[..., None] * clouds[qy, qx].astype(np.float64)
               for qx, qy, weight in upsample_weights(cloud_depth, px, py, wp, near, far, edge))
