"""numpy float64 references of the off-screen clouds' depth and composite draws (:mod:`.offscreen`).

Images are (h, w, ...) in GL row order (row 0 at the bottom). The sprites drawn off screen fade against
:func:`far_depth` (:func:`atmos.plugins.cloud_render.reference.soft_fade`).
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.cloud_render.offscreen import EDGE, low_size


def far_depth(depth: np.ndarray, factor: int) -> np.ndarray:
    """The low-res depth: the largest ``depth`` in each factor × factor block (blocks cut at the edge)."""
    h, w = depth.shape
    lw, lh = low_size((w, h), factor)
    padded = np.full((lh * factor, lw * factor), -np.inf)
    padded[:h, :w] = depth
    return padded.reshape(lh, factor, lw, factor).max(axis=(1, 3))


def composite(clouds: np.ndarray, cloud_depth: np.ndarray, scene_depth: np.ndarray, factor: int,
              near: float, far: float, edge: float = EDGE) -> np.ndarray:
    """(h, w, 4) premultiplied clouds at full resolution: bilinear between the four nearest low-res
    texels unless one's view depth differs from the pixel's by more than ``edge`` (relative), then
    the texel nearest in depth (the first of equals, in the order (0,0), (1,0), (0,1), (1,1))."""
    h, w = scene_depth.shape
    lh, lw = cloud_depth.shape
    inv = lambda d: (1.0 - d) / near + d / far          # 1 / view depth, linear in window depth
    ys, xs = np.mgrid[0:h, 0:w]
    px, py = (xs + 0.5) / factor - 0.5, (ys + 0.5) / factor - 0.5
    x0, y0 = np.floor(px).astype(int), np.floor(py).astype(int)
    fx, fy = px - x0, py - y0
    wp = inv(scene_depth.astype(np.float64))
    total = np.zeros((h, w, 4))
    nearest = np.zeros((h, w, 4))
    best = np.full((h, w), np.inf)
    is_edge = np.zeros((h, w), bool)
    for ox, oy in ((0, 0), (1, 0), (0, 1), (1, 1)):
        qx, qy = np.clip(x0 + ox, 0, lw - 1), np.clip(y0 + oy, 0, lh - 1)
        c = clouds[qy, qx].astype(np.float64)
        wq = inv(cloud_depth[qy, qx].astype(np.float64))
        rel = np.abs(wp - wq) / np.maximum(np.minimum(wp, wq), 1e-30)
        weight = (fx if ox else 1 - fx) * (fy if oy else 1 - fy)
        total += weight[..., None] * c
        is_edge |= rel > edge
        closer = rel < best
        best = np.where(closer, rel, best)
        nearest = np.where(closer[..., None], c, nearest)
    return np.where(is_edge[..., None], nearest, total)
