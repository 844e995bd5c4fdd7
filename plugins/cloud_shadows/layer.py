"""CloudLayer: where the cloud volume's cells are in the world (the placement every cloud effect shares)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CloudLayer:
    """Cell ``(i, j, k)`` of a ``shape = (nx, ny, nz)`` volume has its centre at
    ``((origin.x + i + 0.5)·cx, base_altitude + (j + 0.5)·cy, (origin.z + k + 0.5)·cz)``;
    ``origin`` in cells (the VolumeOrigin), ``cell_size`` = (cx, cy, cz) metres."""

    shape: tuple
    origin: tuple
    cell_size: tuple
    base_altitude: float

    @classmethod
    def of(cls, sim, origin, params) -> "CloudLayer":
        """The layer of a CloudSimulation ``sim`` at VolumeOrigin ``origin`` with CloudShadowParams ``params``."""
        cell = params.cell_size if params.cell_size is not None else sim.settings.cell_size
        return cls(tuple(int(n) for n in sim.shape), tuple(float(v) for v in origin.as_tuple()),
                   tuple(float(c) for c in cell), float(params.base_altitude))

    @property
    def bottom(self) -> float:
        return self.base_altitude

    @property
    def thickness(self) -> float:
        return self.shape[1] * self.cell_size[1]

    def map_coords(self, x, z) -> np.ndarray:
        """World (x, z) → texel coordinates of the top-view maps (texel (i, k) centred at (i, k)), (..., 2)."""
        return np.stack([np.asarray(x, np.float64) / self.cell_size[0] - self.origin[0] - 0.5,
                         np.asarray(z, np.float64) / self.cell_size[2] - self.origin[2] - 0.5], axis=-1)
