"""Frustum culling of boxes on the CPU (thesis 7.2.1): the 6 planes of a view-projection matrix."""
from __future__ import annotations

import numpy as np


def frustum_planes(view_proj: np.ndarray) -> np.ndarray:
    """(6, 4) planes ``(n, d)`` with ``n . p + d >= 0`` inside, from the rows of the (OpenGL)
    matrix: left, right, bottom, top, near, far (Gribb–Hartmann), float64, not normalized."""
    return _ROWS @ np.asarray(view_proj, np.float64)     # w ± x, w ± y, w ± z: the same sums, one call


_ROWS = np.array([[1.0, 0, 0, 1], [-1, 0, 0, 1], [0, 1, 0, 1], [0, -1, 0, 1], [0, 0, 1, 1], [0, 0, -1, 1]])


def boxes_outside(planes: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Bool (...,): True where the box ``[lo, hi]`` lies wholly on the outer side of some plane
    (its corner farthest along the plane normal is outside). Boxes crossing a plane are kept."""
    n = planes[:, :3]
    far_corner = np.where(n > 0, hi[..., None, :], lo[..., None, :])        # (..., 6, 3)
    dist = (far_corner * n).sum(-1) + planes[:, 3]
    return (dist < 0).any(-1)
