"""The terrain mesh: heights, normals and triangle indices of a regular grid (numpy, no GL)."""
from __future__ import annotations

import numpy as np


def height(x, z, relief: float = 30.0, size: float = 256.0) -> np.ndarray:
    """Rolling hills around a winding valley along z (the valley floor near 0), features scaled with ``size``."""
    k = 256.0 / size
    x, z = np.asarray(x, np.float64) * k, np.asarray(z, np.float64) * k
    valley_x = 18.0 * np.sin(z / 45.0)
    valley = 1.0 - np.exp(-((x - valley_x) / 38.0) ** 2)
    hills = 0.35 * np.sin(x / 23.0 + 1.3) * np.cos(z / 31.0) + 0.2 * np.sin((x + z) / 13.0) * np.sin(z / 17.0)
    return relief * (valley * (0.8 + hills) + 0.06 * np.sin(x / 7.0) * np.cos(z / 9.0))


def triangle_count(cells: int) -> int:
    return 2 * cells * cells


def heightfield(size: float = 256.0, cells: int = 71, relief: float = 30.0):
    """Interleaved float32 vertices (position xyz, normal xyz) and uint32 triangle indices of a
    ``cells`` × ``cells`` grid ``size`` metres wide, centred on the origin."""
    if not (isinstance(cells, int) and 1 <= cells <= 1024):
        raise ValueError(f"terrain cells must be an int in 1..1024, got {cells!r}")
    if not size > 0:
        raise ValueError(f"terrain size must be > 0 metres, got {size!r}")
    n = cells + 1
    axis = np.linspace(-size / 2, size / 2, n)
    x, z = np.meshgrid(axis, axis, indexing="ij")
    y = height(x, z, relief, size)
    e = 0.5 * size / cells
    dx = (height(x + e, z, relief, size) - height(x - e, z, relief, size)) / (2 * e)
    dz = (height(x, z + e, relief, size) - height(x, z - e, relief, size)) / (2 * e)
    normal = np.stack([-dx, np.ones_like(dx), -dz], -1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    vertices = np.concatenate([np.stack([x, y, z], -1), normal], -1).reshape(-1, 6).astype(np.float32)
    i = np.arange(n * n).reshape(n, n)[:-1, :-1].ravel()
    quads = np.stack([i, i + n, i + 1, i + 1, i + n, i + n + 1], -1)
    return vertices, quads.astype(np.uint32).ravel()
