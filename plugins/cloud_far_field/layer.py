"""FarFieldLayer: the far field's textures and cover for one frame, shared by every pass that needs it.

The far field's clouds are a function of world (x, z): the four octave textures at
``uv = x/tile_size + drift_k``, each point taking the volume's column sum at its rank (:mod:`.cover`). The far-field
pass draws them; the ground shadows (:mod:`atmos.plugins.cloud_shadows`) darken the ground under them
with the same function (``shaders/cloud_far_field/field.glsl``). The plugin imports this object as the
graph resource ``"far_field"``; each pass that uses it calls :meth:`prepare` (re-bakes the octaves
when the sun turned, measures the cover) and :meth:`use`.
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.cloud_far_field.cover import QUANTILES, level_table
from atmos.plugins.cloud_render.light import light_uniforms
from atmos.plugins.clouds.sets import CloudSets
from atmos.plugins.sky_layer.octaves import OctaveTextures

FAR_FIELD = "far_field"          # the imported graph resource
REBAKE_TOLERANCE = 0.05          # re-bake the octaves when the sun moved the light step by this fraction
OCTAVE_UNIT = 5                  # texture units 5..8 (field.glsl)


def drift(settings, sets: CloudSets, time: float) -> np.ndarray:
    """(4, 2) offsets of the octaves in tiles, wrapped to [0, 1). ``settings.wind`` None: the distance
    the simulated clouds have moved with their wind (``CloudSets.wind_travel``, cells × cell size), so
    both move together; a tuple: that (x, z) drift in m/s with the App clock ``time``."""
    if settings.wind is None:
        metres = np.asarray(sets.wind_travel, np.float64) * np.asarray(sets.settings.cell_size, np.float64)[[0, 2]]
    else:
        metres = np.asarray(settings.wind, np.float64) * float(time)
    return np.mod(np.broadcast_to(metres / settings.tile_size, (4, 2)), 1.0)


def column_tau(settings, sets: CloudSets) -> float:
    """field.glsl's field_column_tau: optical depth per cell of a column sum, ``thickness · sigma_t ·
    cell height`` (the column far.frag draws and the ground shadows take beyond the volume)."""
    medium = sets.settings
    return float(settings.thickness * medium.sigma_t * medium.cell_size[1])


class FarFieldLayer:
    """The octave textures and the measured cover of the far field (GL objects of one GpuContext)."""

    def __init__(self, gpu, plugin):
        self.gpu, self.plugin = gpu, plugin
        self.octaves = OctaveTextures(gpu)
        self.cover_program = gpu.program(compute_shader="cloud_far_field/cover.comp")
        self.cover = gpu.track(gpu.ctx.buffer(reserve=4 * (1 + QUANTILES)))   # cover, column_quantiles
        self._prepared = None                # the SceneView of the frame prepared last (held: never a reused id)

    @property
    def settings(self):
        return self.plugin.settings

    def prepare(self, view, sim: CloudSets) -> None:
        """Bake (when needed) and measure the cover (one small dispatch), once per frame: every user
        (the far-field pass or the march, the shadows, the shafts) calls it, the first one does it."""
        if view is self._prepared:
            return
        self._prepared = view
        params = self.settings
        sun_dir = light_uniforms(sim.settings, view.sun)["sun_dir"]
        if self.octaves.needs_bake(params, sun_dir, REBAKE_TOLERANCE):
            self.octaves.bake(params, sun_dir)
        self.measure_cover(sim)

    def measure_cover(self, sim: CloudSets) -> None:
        """The simulation's edge-weighted cover and column-sum quantiles into the buffer the shaders
        read (float32: cover, then QUANTILES column sums in cells; :meth:`read_cover`)."""
        c = self.cover_program
        sim.maps_of(sim.a).sums.use(0)
        sim.maps_of(sim.b).sums.use(1)
        c["t"].value = float(sim.t)
        c["a_shift"].value = sim.a_shift[0], sim.a_shift[2]
        c["threshold"].value = float(sim.settings.cover_threshold)
        c["edge_fade"].value = float(sim.settings.edge_fade)
        c["max_sum"].value = float(sim.shape[1])
        self.cover.bind_to_storage_buffer(0)
        c.run(1)
        self.gpu.ctx.memory_barrier()

    def read_cover(self) -> tuple[float, np.ndarray]:
        """(cover, (QUANTILES,) column-sum quantiles) as last measured (a GPU → CPU copy: tests and tools)."""
        values = np.frombuffer(self.cover.read(), np.float32).astype(np.float64)
        return float(values[0]), values[1:]

    def use(self, program, view, sim: CloudSets) -> None:
        """Bind the textures (units 5..8), the cover (storage buffer 0) and set field.glsl's uniforms."""
        params = self.settings
        self.octaves.use(OCTAVE_UNIT)
        self.cover.bind_to_storage_buffer(0)
        time = float(view.time) if params.animate else 0.0
        layout = sim.layout()
        camera = np.asarray(view.camera.position, np.float64)
        values = dict(field_origin=tuple(camera[[0, 2]]), field_origin_uv=tuple(np.mod(camera[[0, 2]] / params.tile_size, 1.0)),
                      field_tile_size=float(params.tile_size),
                      field_mid_height=float(0.5 * (layout.lo[1] + layout.hi[1])),
                      field_column_tau=column_tau(params, sim))
        for name, value in values.items():
            if name in program:
                program[name].value = value
        program["field_offsets"].write(drift(params, sim, time).astype("f4").tobytes())
        quantiles, first = level_table(params.base_frequency, params.seed, params.size)
        program["field_quantiles"].write(np.asarray(quantiles, "f4").tobytes())
        if "field_first_level" in program:
            program["field_first_level"].value = first

    def release(self) -> None:
        if self.octaves is not None:
            self.octaves.release()
            self.octaves = None
        if self.cover is not None:
            self.cover.release()
            self.cover = None
