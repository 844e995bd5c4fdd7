"""Where the cloud volume sits in the world, and the bounding boxes of its sprite-group columns.

Placement rule: cell ``(i, j, k)`` of a volume of ``shape = (nx, ny, nz)`` cells of world size
``cell = (cx, cy, cz)`` has its centre at ``((ox + i + 0.5) * cx, base + (j + 0.5) * cy,
(oz + k + 0.5) * cz)``, where ``(ox, oz)`` are the :class:`VolumeOrigin`'s x and z (in cells; it
moves with the viewer) and ``base`` is the world height of the layer's bottom. A column ``(gi, gk)``
holds the cells ``x in [gi * gx, min((gi + 1) * gx, nx))`` and likewise z, all heights (7.2.1).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True)
class CloudLayout:
    """The world placement of one volume; see the module docstring. ``pad``: world margin added to
    each column box (the sprite radius, so sprites reaching into view are never culled)."""
    shape: tuple
    cell: tuple
    origin_xz: tuple
    base: float
    group: tuple
    pad: float = 0.0

    @cached_property
    def lo(self) -> np.ndarray:
        """World corner of the layer's cell (0, 0, 0) face (read-only: worked out once)."""
        lo = np.array([self.origin_xz[0] * self.cell[0], self.base, self.origin_xz[1] * self.cell[2]])
        lo.flags.writeable = False
        return lo

    @property
    def heights(self) -> tuple[float, float]:
        """(base, top) world y of the layer, over which the cloud light takes the sun's colour
        (``Sun.color_at``, :func:`atmos.plugins.clouds.volume.light.sun_colors`)."""
        return float(self.base), float(self.base + self.shape[1] * self.cell[1])

    @cached_property
    def hi(self) -> np.ndarray:
        """World corner of the layer's far top face (read-only: worked out once)."""
        hi = self.lo + np.asarray(self.shape, float) * np.asarray(self.cell, float)
        hi.flags.writeable = False
        return hi

    @property
    def grid(self) -> tuple[int, int]:
        """Columns along x and z: ceil(nx / gx), ceil(nz / gz)."""
        return -(-self.shape[0] // self.group[0]), -(-self.shape[2] // self.group[1])

    def cell_centers(self, cells) -> np.ndarray:
        """World centres (..., 3) of integer cells (..., 3)."""
        return self.lo + (np.asarray(cells, float) + 0.5) * np.asarray(self.cell, float)

    def slice_heights(self) -> np.ndarray:
        """World y of every height slice's cell centres, (ny,)."""
        return self.base + (np.arange(self.shape[1]) + 0.5) * self.cell[1]

    def column_boxes(self, pad_scale=1.0) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) world boxes of every column, each (gx, gz, 3), padded by ``pad × pad_scale``
        (a number, or one per column as (gx, gz))."""
        gx, gz = self.grid
        cell = np.asarray(self.cell, float)
        i = np.arange(gx)[:, None]
        k = np.arange(gz)[None, :]
        lo_cells = np.stack(np.broadcast_arrays(i * self.group[0], 0 * i * k, k * self.group[1]), -1)
        hi_cells = np.stack(np.broadcast_arrays(np.minimum((i + 1) * self.group[0], self.shape[0]),
                                                0 * i * k + self.shape[1],
                                                np.minimum((k + 1) * self.group[1], self.shape[2])), -1)
        pad = self.pad * np.asarray(pad_scale, float)[..., None]
        return self.lo + lo_cells * cell - pad, self.lo + hi_cells * cell + pad
