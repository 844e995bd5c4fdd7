"""StaticClouds: a given density volume drawn as clouds, no automaton or weather (``CloudsPlugin(density=...)``).

The volume ``[x, y, z]`` is uploaded once into one texture set shown as both A and B (t = 0) and
placed by :mod:`atmos.plugins.clouds.volume.layout` at the current :class:`VolumeOrigin`; its density maps
and light-volume columns are computed once, its transmittance toward the sun and (while a renderer reads
it: :mod:`~atmos.plugins.clouds.volume.field_demand`) its diffusion field (:mod:`atmos.plugins.clouds.light.diffusion`) again
whenever the sun's direction, the medium or the demand changes (checked each frame, when the graph asks
for ``"cloud_sets"``).
"""
from __future__ import annotations

import numpy as np

from atmos.slicing import TextureSet
from atmos.graph import TextureDesc
from atmos.plugins.clouds.simulation.density_maps import DensityMaps
from atmos.plugins.clouds.volume.sets import CloudSets
from atmos.plugins.clouds.light import grid
from atmos.plugins.clouds.light.columns import COLUMNS, ColumnShader, column_desc
from atmos.plugins.clouds.volume.field_demand import FieldDemand
from atmos.plugins.clouds.light.diffusion import DiffusionTask, field_medium
from atmos.plugins.clouds.light.shear_warp import ShearWarpShader


class StaticClouds:
    """Answers ``sets()``, ``view()``, ``max_maps()``, ``layout()`` like a CloudSimulation."""

    def __init__(self, gpu, density, settings, origin, sun, demand: FieldDemand | None = None):
        volume = grid.check_density(density)
        self.shape = tuple(volume.shape)
        self.settings, self.origin, self.sun = settings, origin, sun
        self.demand = demand or FieldDemand()
        self.drawn = None                # the DrawnShape its CloudSets carry (CloudsPlugin sets it)
        s = settings
        descs = {"density": TextureDesc(self.shape, 1, "f4"), COLUMNS: column_desc(self.shape, s.shading_scale)}
        if s.shading:
            descs["transmittance"] = TextureDesc(grid.shading_shape(self.shape, s.shading_scale), 1, "f2")
        self.set = TextureSet.create(gpu, descs, "static")
        self.shader = self.maps = self.field = None
        try:
            self.set["density"].write(np.ascontiguousarray(volume.transpose(2, 1, 0)).tobytes())
            self.maps = DensityMaps(gpu, self.shape, s.band_height, s.group_size)
            self.maps.run(self.set["density"])
            self._max = self.maps.read_max_maps()
            ColumnShader(gpu, self.shape, s.shading_scale).run(self.set["density"], self.set[COLUMNS])
            if s.shading:
                self.shader = ShearWarpShader(gpu, self.shape, s.shading_scale)
                self.field = DiffusionTask(gpu, self.shape, s.shading_scale,
                                           lambda: field_medium(self.settings, self.sun()), self.demand.wanted)
        except Exception:
            self.release()
            raise
        self._shaded = None

    def _shade(self) -> None:
        if self.shader is None:
            return
        sun = np.asarray(self.sun(), np.float64)
        s = self.settings
        wanted = self.demand.wanted()
        key = (tuple(sun), s.sigma_t, s.scattering, tuple(s.cell_size), s.albedo, s.phase,
               wanted)
        if key == self._shaded:
            return
        self.shader.begin(self.set["density"], sun / np.asarray(self.settings.cell_size, float),
                          self.settings.shading_sigma(sun), target=self.set["transmittance"])
        self.shader.run_all()
        self.field.solve(self.set)
        self.set.version += 1           # its light is new: what was derived from it is out of date
        self._shaded = key

    def sets(self) -> CloudSets:
        self._shade()
        here = self.origin.as_tuple()
        return CloudSets(self.set, self.set, 0.0, self.maps, self.maps, self._max, self._max, here, here, here,
                         self.settings, self.shape, drawn=self.drawn)

    def view(self):
        return self.set, self.set, 0.0

    def max_maps(self) -> np.ndarray:
        return self._max

    def maps_of(self, texture_set) -> DensityMaps:
        return self.maps

    def layout(self, base_altitude=None, cell_size=None, pad: float = 0.0):
        return self.sets().layout(base_altitude, cell_size, pad)

    def release(self) -> None:
        for obj in (self.shader, self.field, self.maps, self.set):
            if obj is not None:
                obj.release()
        self.shader = self.field = self.maps = self.set = None
