"""CloudSets: the cloud simulation's texture sets as the render graph's imported resource ``"cloud_sets"``."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from atmos.slicing import TextureSet
from atmos.plugins.clouds.simulation.density_maps import DensityMaps
from atmos.plugins.clouds.volume.layout import CloudLayout

CLOUD_SETS = "cloud_sets"
FAR_FIELD = "far_field"         # the cloud far field's layer (a FarFieldLayer), imported by CloudFarFieldPlugin
CLOUD_VOLUME = "cloud volume"   # RenderPass.exclusive of the passes that draw the volume: one renderer a frame


@dataclass(frozen=True)
class CloudSets:
    """What cloud passes read this frame: sets A and B (draw ``mix(A, B, t)``), their density maps,
    the world placement (VolumeOrigin x, y, z in cells) each set was computed at and the one now.

    Each set is drawn where it was computed (the automaton shifts its contents when the origin
    moves): :meth:`layout` is B's placement, and A's cell for B's cell ``c`` is ``c + a_shift``
    (renderers sample A through that offset, so a moving volume never jumps at a step boundary).

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
    wind_travel: tuple = (0.0, 0.0)   # (x, z) cells the contents have moved with the wind, mix(A's, B's, t)
    drawn: object = None         # the DrawnShape (volume/shape.py) column readers shape the columns by; None: none

    def view(self) -> tuple[TextureSet, TextureSet, float]:
        return self.a, self.b, self.t

    def maps_of(self, texture_set) -> DensityMaps:
        if texture_set is self.a:
            return self.maps_a
        if texture_set is self.b:
            return self.maps_b
        raise ValueError("CloudSets.maps_of: only sets A and B of this frame have maps here")

    @property
    def a_shift(self) -> tuple[int, int, int]:
        """Whole cells (x, 0, z) from B's cell to A's at the same world point: placement B − placement A."""
        return (int(round(self.placement_b[0] - self.placement_a[0])), 0,
                int(round(self.placement_b[2] - self.placement_a[2])))

    def max_maps(self) -> np.ndarray:
        """Elementwise max of B's max maps and A's over the groups A's cells of each B group fall in
        (A sampled through :attr:`a_shift`): a segment whose value is 0 is empty in both (7.2.2)."""
        return np.maximum(shifted_max(self.max_a, self.a_shift, self.settings.group_size), self.max_b)

    def layout(self, base_altitude: float | None = None, cell_size=None, pad: float = 0.0) -> CloudLayout:
        """Where the sets are drawn: B's placement (see :meth:`CloudSimulation.layout`); the default one
        worked out once per frame's sets."""
        if base_altitude is None and cell_size is None and pad == 0.0:
            try:
                return self.__dict__["_layout"]
            except KeyError:
                layout = self.__dict__["_layout"] = self._layout_of(None, None, 0.0)
                return layout
        return self._layout_of(base_altitude, cell_size, pad)

    def _layout_of(self, base_altitude, cell_size, pad: float) -> CloudLayout:
        s = self.settings
        cell = tuple(map(float, s.cell_size if cell_size is None else cell_size))
        base = float(s.base_altitude if base_altitude is None else base_altitude)
        return CloudLayout(tuple(self.shape), cell, (float(self.placement_b[0]), float(self.placement_b[2])), base,
                           tuple(s.group_size), pad)


def shifted_max(max_map: np.ndarray, shift, group) -> np.ndarray:
    """Max maps (layers, gx, gz) of a set sampled ``shift`` cells (x, _, z) off, on the unshifted group
    grid: group g covers the shifted set's cells [g·G + s, (g + 1)·G + s), i.e. at most two of its
    groups per axis; groups past the edge count as empty."""
    out = np.asarray(max_map)
    for axis, s, g in ((1, shift[0], group[0]), (2, shift[2], group[1])):
        if s == 0:
            continue
        n = out.shape[axis]
        index = np.arange(n)
        lo, hi = (index * g + s) // g, ((index + 1) * g + s - 1) // g
        padded = np.concatenate([np.zeros_like(out.take([0], axis)), out, np.zeros_like(out.take([0], axis))], axis)
        pick = lambda k: padded.take(np.clip(k, -1, n) + 1, axis)   # -1 and n: the empty pads
        out = np.maximum(pick(lo), pick(hi))
    return out
