"""CloudSets: the cloud simulation's texture sets as the render graph's imported resource ``"cloud_sets"``."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from atmos.frames import TextureSet
from atmos.plugins.clouds.density_maps import DensityMaps
from atmos.plugins.clouds.layout import CloudLayout

CLOUD_SETS = "cloud_sets"


@dataclass(frozen=True)
class CloudSets:
    """What cloud passes read this frame: sets A and B (draw ``mix(A, B, t)``), their density maps,
    the world placement (VolumeOrigin x, y, z in cells) each set was computed at and the one now.

    It answers ``view()``, ``maps_of()``, ``max_maps()``, ``layout()`` and ``settings`` like the
    :class:`~atmos.plugins.clouds.CloudSimulation` it comes from, so helpers take either.
    """
    a: TextureSet
    b: TextureSet
    t: float
    maps_a: DensityMaps
    maps_b: DensityMaps
    max_a: np.ndarray            # (1 + bands, gx, gz) max maps of A and of B
    max_b: np.ndarray
    placement_a: tuple           # VolumeOrigin (x, y, z) when A's step began
    placement_b: tuple
    origin: tuple                # VolumeOrigin now
    settings: object             # the simulation's CloudSettings
    shape: tuple

    def view(self) -> tuple[TextureSet, TextureSet, float]:
        return self.a, self.b, self.t

    def maps_of(self, texture_set) -> DensityMaps:
        if texture_set is self.a:
            return self.maps_a
        if texture_set is self.b:
            return self.maps_b
        raise ValueError("CloudSets.maps_of: only sets A and B of this frame have maps here")

    def max_maps(self) -> np.ndarray:
        """Elementwise max of A's and B's max maps: a segment whose value is 0 is empty in both (7.2.2)."""
        return np.maximum(self.max_a, self.max_b)

    def layout(self, base_altitude: float | None = None, cell_size=None, pad: float = 0.0) -> CloudLayout:
        """The volume's world placement now (see :meth:`CloudSimulation.layout`)."""
        s = self.settings
        cell = tuple(float(c) for c in (s.cell_size if cell_size is None else cell_size))
        base = float(s.base_altitude if base_altitude is None else base_altitude)
        return CloudLayout(tuple(self.shape), cell, (float(self.origin[0]), float(self.origin[2])), base,
                           tuple(s.group_size), pad)
