"""The terrain mesh: heights, normals and triangle indices of a grid (numpy, no GL).

:func:`heightfield` is the near square (a regular grid, what collision tests against);
:func:`terrain_mesh` is what is drawn: the same square continued to the horizon by a far ring whose
cells grow outward by ``FAR_GROWTH`` per step. Both are one tensor-product grid (shared x and z
axes): the far ring's vertices on the square's border are the square's own vertices, so there is no
seam, gap or T-junction, and its heights come from the same :func:`height` formula.
"""
from __future__ import annotations

import numpy as np

#: Each step of the far ring is this much wider than the one inside it (the first is one near cell).
FAR_GROWTH = 1.2


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


def _check(size, cells) -> None:
    if not (isinstance(cells, int) and 1 <= cells <= 1024):
        raise ValueError(f"terrain cells must be an int in 1..1024, got {cells!r}")
    if not size > 0:
        raise ValueError(f"terrain size must be > 0 metres, got {size!r}")


def grid_mesh(x_axis, z_axis, relief: float, size: float):
    """Interleaved float32 vertices (position xyz, normal xyz) and uint32 triangle indices of the grid
    over increasing ``x_axis`` × ``z_axis`` (float64 metres), heights from :func:`height`. Each normal
    is the height's slope by central differences half the local grid step apart (the mesh's own
    resolution: no detail it cannot show). Quad (a, b) holds triangles 2(a(nz-1)+b) and that + 1."""
    x_axis, z_axis = np.asarray(x_axis, np.float64), np.asarray(z_axis, np.float64)
    x, z = np.meshgrid(x_axis, z_axis, indexing="ij")
    y = height(x, z, relief, size)
    ex, ez = np.meshgrid(_half_steps(x_axis), _half_steps(z_axis), indexing="ij")
    dx = (height(x + ex, z, relief, size) - height(x - ex, z, relief, size)) / (2 * ex)
    dz = (height(x, z + ez, relief, size) - height(x, z - ez, relief, size)) / (2 * ez)
    normal = np.stack([-dx, np.ones_like(dx), -dz], -1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    vertices = np.concatenate([np.stack([x, y, z], -1), normal], -1).reshape(-1, 6).astype(np.float32)
    nx, nz = x_axis.size, z_axis.size
    i = np.arange(nx * nz).reshape(nx, nz)[:-1, :-1].ravel()
    quads = np.stack([i, i + nz, i + 1, i + 1, i + nz, i + nz + 1], -1)
    return vertices, quads.astype(np.uint32).ravel()


def _half_steps(axis: np.ndarray) -> np.ndarray:
    """Half the mean of the steps on either side of each point (one side at the ends)."""
    step = np.diff(axis)
    return 0.25 * (np.concatenate([step[:1], step]) + np.concatenate([step, step[-1:]]))


def heightfield(size: float = 256.0, cells: int = 71, relief: float = 30.0):
    """Interleaved float32 vertices (position xyz, normal xyz) and uint32 triangle indices of a
    ``cells`` × ``cells`` grid ``size`` metres wide, centred on the origin."""
    _check(size, cells)
    axis = np.linspace(-size / 2, size / 2, cells + 1)
    return grid_mesh(axis, axis, relief, size)


def terrain_axis(size: float, cells: int, horizon: float) -> np.ndarray:
    """The drawn mesh's x (and z) coordinates: the square's ``cells + 1`` points, then on each side
    steps growing by ``FAR_GROWTH`` from one cell (size / cells) until ``horizon`` metres from the
    origin (the last step ends exactly there). ``horizon <= size / 2``: the square alone."""
    _check(size, cells)
    near = np.linspace(-size / 2, size / 2, cells + 1)
    if not horizon > size / 2:
        return near
    cell, edge, far = size / cells, size / 2, []
    while edge < horizon:
        cell *= FAR_GROWTH
        edge += cell
        far.append(edge)
    far[-1] = horizon
    if len(far) > 1 and far[-1] - far[-2] < 0.5 * (far[-2] - (far[-3] if len(far) > 2 else size / 2)):
        del far[-2]                        # no sliver step at the end
    far = np.array(far)
    return np.concatenate([-far[::-1], near, far])


def terrain_mesh(size: float = 256.0, cells: int = 71, relief: float = 30.0, horizon: float = 0.0):
    """The drawn terrain: :func:`grid_mesh` over :func:`terrain_axis` in x and z (the square of
    :func:`heightfield`, vertex for vertex, inside a far ring to ``horizon``)."""
    axis = terrain_axis(size, cells, horizon)
    return grid_mesh(axis, axis, relief, size)
