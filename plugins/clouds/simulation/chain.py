"""The cloud simulation chain as a sliced job into three texture sets (thesis 7.1).

One simulation step = region volume (weather rules + ellipsoids rendered into the region volume
and its probabilities) → automaton step (driven by the region's probability texture, advected by
the wind and by the volume's own motion) → smoothing (``smoothing_slices`` z ranges) → density
maps (the same z ranges; the tiny max maps are copied into a pixel buffer once per step and read
when the set is first drawn, frames later: no stall) → columns (the light volume's density integrals
up and down, :mod:`atmos.plugins.clouds.light.columns`, the same number of z ranges) → shading (inverse
shear-warp transmittance toward the sun, a few light-space slices per job slice; optional) → with the
shading, the diffusion field in the steps a renderer reads it (:mod:`atmos.plugins.clouds.light.diffusion`: CG iterations
over 8 job slices; :mod:`~atmos.plugins.clouds.volume.field_demand`). The frame scheduler runs
a few slices per frame into set C while the renderer draws sets A and B interpolated; nothing but
the max maps comes back to the CPU.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from atmos.checks import (CheckedSettings, bool_field, check_int, choice_field, int_field, is_int, nested_field,
                          num_field, vec_field)

from atmos.phase import Phase
from atmos.slicing import SlicedJob, SliceTask, TripleSet
from atmos.graph import TextureDesc
from atmos.plugins.clouds.automaton import CloudAutomaton
from atmos.plugins.clouds.simulation.density_maps import DensityMaps
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.volume.sets import CloudSets
from atmos.plugins.clouds.simulation.smoothing import FORMATS, WEIGHTS, Smoother, slice_range
from atmos.plugins.clouds.light.columns import COLUMNS, ColumnShader, ColumnTask, column_desc
from atmos.plugins.clouds.light.diffusion import DiffusionTask, field_medium
from atmos.plugins.clouds.volume.field_demand import FieldDemand
from atmos.plugins.clouds.light.grid import check_scale, shading_shape
from atmos.plugins.clouds.light.medium import cell_sigma
from atmos.plugins.clouds.light.scattering import Scattering
from atmos.plugins.clouds.light.shear_warp import ShadingTask, ShearWarpShader
from atmos.plugins.clouds.weather import RegionVolume, VolumeOrigin, WeatherSettings, ellipsoid_array, step_weather


@dataclass(frozen=True)
class CloudSettings(CheckedSettings):
    """How the cloud chain is computed, and the weather it is computed from. The medium and its light
    are in physical units (:mod:`atmos.plugins.clouds.light.medium`); the thesis's per-cell sigma is
    derived (:attr:`sigma`).

    Live (the next step, or the next frame for placement and light): ``weather`` (but its
    ``volume_shape``), ``step_seconds``, ``cover_threshold``, the medium and light fields,
    ``scattering``, ``cell_size``, ``base_altitude``, ``edge_fade``. FIXED (they size the automaton,
    the textures, the maps and the job's slices): the others.

    Checked by hand (not in the list below):

    ``radius`` = (1, 1, 1): the smoothing neighbourhood (eq. 2.11), an int or three (rx, ry, rz), each 0..8.
    ``group_size`` = (32, 32): cells per sprite group, the grid the density maps are max-downsampled
    to, an int or two (group_x, group_z), each 1..4096.
    ``smoothing_slices`` = 4: z ranges the smoothing and density maps are split into, 1..nz of
    ``weather.volume_shape``.
    ``scattering`` = None: single or Harris multiple forward scattering (a :class:`Scattering`; None:
    single).
    ``shading_scale`` = 1: the shading's resolution, 1, 2 or 4 (full, half, quarter).
    """
    weather: WeatherSettings = nested_field(WeatherSettings(), "the ellipsoids and probabilities "
                                            "(``configure(weather={\"cloud_density\": 200})`` changes single "
                                            "fields of it)")
    step_seconds: float = num_field(1.0, 0.0, doc="weather time one simulation step represents", lo_open=True)
    layout: str = choice_field("packed", ("packed", "cell"), "the automaton's layout")
    density_dtype: str = choice_field("f2", FORMATS, "the smoothed density's texture format")
    radius: tuple = (1, 1, 1)
    weights: str = choice_field("tent", WEIGHTS, "the smoothing's weights (eq. 2.11)")
    band_height: int = int_field(4, 1, 4096, "height slices per band of the density maps")
    group_size: tuple = (32, 32)
    smoothing_slices: int = 4
    cover_threshold: float = num_field(0.5, 0.0, doc="a column counts as covered when its summed density "
                                       "exceeds this (cells)")
    shading: bool = bool_field(True, "the shading toward the sun (thesis ch. 5) on or off")
    sigma_t: float = num_field(0.6, 0.0, doc="extinction in 1/m at density 1")
    albedo: float = num_field(1.0, 0.0, 1.0, "single-scattering albedo")
    phase: Phase = nested_field(Phase(0.85, -0.3, 0.1), "the cloud droplets' two-lobe phase function")
    sun_intensity: float = num_field(4.0 * math.pi, 0.0, doc="sun irradiance = this × ``Sun.color``")
    sky_intensity: float = num_field(1.0, 0.0, doc="sky radiance = this × ``Sun.ambient``")
    ground_albedo: float = num_field(0.3, 0.0, 1.0, "the ground's albedo (light from below) where the scene "
                                     "publishes no GroundSurface (terrain and ground plane do)")
    scattering: Scattering | None = None
    shading_scale: int = 1
    shading_slices_per_run: int = int_field(8, 1, 4096, "light-space slices per job slice of the shading")
    cell_size: tuple = vec_field((1.0, 1.0, 1.0), 3, "positive", "the world size of a cell (x, y, z; m), so the "
                                 "sun direction is taken into cell units (cells need not be cubes)", lo=1e-3)
    base_altitude: float = num_field(100.0, doc="world y of the volume's bottom "
                                     "(:mod:`atmos.plugins.clouds.volume.layout`)")
    edge_fade: float = num_field(0.0, 0.0, 1.0, "the renderers fade the density to 0 over this outer fraction of "
                                 "the volume's half width, toward its inscribed circle "
                                 "(:mod:`atmos.plugins.clouds.volume.edge`; 0: the square)")

    FIXED = ("layout", "density_dtype", "radius", "weights", "band_height", "group_size", "smoothing_slices",
             "shading", "shading_scale", "shading_slices_per_run")

    def __post_init__(self):
        super().__post_init__()
        o = "CloudSettings"
        nz = self.weather.volume_shape[2]
        radius = (self.radius,) * 3 if is_int(self.radius) else self.radius
        group = (self.group_size,) * 2 if is_int(self.group_size) else self.group_size
        try:
            radius, group = tuple(radius), tuple(group)
        except TypeError:
            radius = group = ()
        if len(radius) != 3:
            raise ValueError(f"{o}.radius must be an int or three ints (rx, ry, rz), each 0..8, got {self.radius!r}")
        if len(group) != 2:
            raise ValueError(f"{o}.group_size must be an int or two ints (group_x, group_z), got {self.group_size!r}")
        if self.scattering is not None and not isinstance(self.scattering, Scattering):
            raise ValueError(f"{o}.scattering must be None or a Scattering, got {self.scattering!r}")
        try:
            shading_scale = check_scale(self.shading_scale)
        except ValueError:
            raise ValueError(f"{o}.shading_scale must be 1, 2 or 4 (full, half, quarter resolution), "
                             f"got {self.shading_scale!r}") from None
        self.store(dict(
            radius=tuple(check_int(o, f"radius[{i}]", r, 0, 8) for i, r in enumerate(radius)),
            group_size=tuple(check_int(o, f"group_size[{i}]", g, 1, 4096) for i, g in enumerate(group)),
            smoothing_slices=check_int(o, "smoothing_slices", self.smoothing_slices, 1, nz),
            shading_scale=shading_scale,
        ))

    @cached_property
    def sigma(self) -> float:
        """Derived: extinction per cube-root cell length at density 1, ``sigma_t × cbrt(cx cy cz)``
        (computed once per settings object: they are frozen)."""
        return float(self.sigma_t * np.cbrt(np.prod(self.cell_size)))

    def shading_sigma(self, sun_dir) -> float:
        """The shear-warp's extinction per index-space length toward ``sun_dir`` (exact for non-cubic
        cells, :func:`atmos.plugins.clouds.light.medium.cell_sigma`), with the scattering model's reduction."""
        return (self.scattering or Scattering()).extinction(cell_sigma(self.sigma_t, self.cell_size, sun_dir))


class CloudSimulation:
    """Weather ellipsoids in ``world`` → cloud density volumes, a few slices per frame.

    ``origin`` is the :class:`VolumeOrigin` (moved by the game with the viewer); ``sun`` a
    zero-argument callable giving the world direction toward the sun (read when a step starts).
    Readers use :meth:`view` (sets A and B, the interpolation factor) and :meth:`max_maps`
    (empty-space skipping); a set's ``["density"]`` is the smoothed density,
    ``["transmittance"]`` (with shading) the transmittance toward the sun at the shading scale,
    ``["columns"]`` the light volume's column integrals (:mod:`atmos.plugins.clouds.light.columns`) at that scale,
    ``["diffusion"]`` (with shading, in the sets of steps where ``demand`` wanted it) the diffusion
    field (:mod:`atmos.plugins.clouds.light.diffusion`),
    and ``maps_of(set).sums`` the top-view sums (layer 0 all heights, then one per height band).
    """

    def __init__(self, gpu, world, settings: CloudSettings | None = None, seed: int = 0,
                 origin: VolumeOrigin | None = None, sun=None, demand: FieldDemand | None = None):
        if settings is not None and not isinstance(settings, CloudSettings):
            raise ValueError(f"CloudSimulation settings must be a CloudSettings, got {type(settings).__name__}")
        self.settings = settings or CloudSettings()      # read live: CloudsPlugin.configure replaces it
        self.drawn = None                # the DrawnShape its CloudSets carry (CloudsPlugin sets it)
        shape = self.settings.weather.volume_shape
        self.shape = shape
        self.world = world
        self.origin = origin or VolumeOrigin()
        self.rng = np.random.default_rng(seed)
        self.gpu = gpu
        self.sun = sun or (lambda: np.array([0.3, 0.35, -0.88]))
        self.shader = self.field = None
        s = self.settings
        made = []
        try:
            self.region = RegionVolume(gpu, shape)
            made.append(self.region)
            self.automaton = CloudAutomaton(gpu, shape, seed=seed, layout=s.layout)
            made.append(self.automaton)
            self.smoother = Smoother.for_automaton(self.automaton, s.radius, s.weights)
            made.append(self.smoother)
            descs = {"density": TextureDesc(shape, 1, s.density_dtype), COLUMNS: column_desc(shape, s.shading_scale)}
            if s.shading:
                descs["transmittance"] = TextureDesc(shading_shape(shape, s.shading_scale), 1, "f2")
                self.shader = ShearWarpShader(gpu, shape, s.shading_scale)
                made.append(self.shader)
            self.triple = TripleSet(gpu, descs)
            made.append(self.triple)
            self._maps = {id(t): DensityMaps(gpu, shape, s.band_height, s.group_size) for t in self.triple.sets}
            made += list(self._maps.values())
        except Exception:
            for obj in made:
                obj.release()
            raise
        self._max_maps = {key: np.zeros((1 + m.bands, *m.grid), np.float32) for key, m in self._maps.items()}
        self._placement: dict[int, tuple] = {}    # id(texture set) -> VolumeOrigin its step began at
        self._drift = np.zeros(2)          # sub-cell wind displacement not yet applied
        self._blown = np.zeros(2)          # cells of wind so far (x, z)
        self._travel: dict[int, np.ndarray] = {}   # id(texture set) -> cells its contents moved with the wind
        self._last_origin = np.array(self.origin.as_tuple())
        self._step_origin = self.origin.as_tuple()
        n = s.smoothing_slices
        tasks = [
            SliceTask("region", 1, self._region_slice),
            SliceTask("automaton", 1, self._automaton_slice),
            SliceTask("smoothing", n, self._smoothing_slice),
            SliceTask("density_maps", n, self._maps_slice),
            ColumnTask(ColumnShader(gpu, shape, s.shading_scale), n),
        ]
        if s.shading:                  # sigma and scattering read when each step's shading begins
            tasks.append(ShadingTask(self.shader, self.sun_in_cells, lambda: self.settings.shading_sigma(self.sun()),
                                       slices_per_run=s.shading_slices_per_run))
            demand = demand or FieldDemand()
            self.field = DiffusionTask(gpu, shape, s.shading_scale, lambda: field_medium(self.settings, self.sun()),
                                       demand.wanted)
            tasks.append(self.field)
        self.job = SlicedJob("clouds", tasks, self.triple, begin=self._begin_step)

    def _begin_step(self, step: int) -> None:
        if self.field is not None:
            self.field.plan(self.triple.c)

    # -- tasks -------------------------------------------------------------------------------
    def warm_up(self, steps: int = 0) -> None:
        """Before the first frame: ``steps`` steps of the weather and the automaton alone (no set would
        show their smoothing, maps, light or field), then whole steps until sets A and B hold results
        (:meth:`SlicedJob.prime`): the same clouds as ``steps`` more whole steps, at a fraction of the cost."""
        for _ in range(steps):
            self._weather_step()
            self._automaton_step()
        self.job.prime()

    def _weather_step(self) -> None:
        origin = self._step_origin = self.origin.as_tuple()
        s = self.settings
        step_weather(self.world, s.weather, self.rng, s.step_seconds, origin)
        self.region.render(ellipsoid_array(self.world, origin))
        self.region.probabilities(s.weather)

    def _automaton_step(self) -> None:
        self.automaton.step_with_texture(self.region.prob_texture, shift=self._next_shift())

    def _region_slice(self, index: int, job) -> None:
        self._weather_step()
        self._placement[id(job.target)] = self._step_origin

    def _automaton_slice(self, index: int, job) -> None:
        self._automaton_step()
        self._travel[id(job.target)] = self._blown - self._drift      # the wind's part of the whole-cell shifts

    def _smoothing_slice(self, index: int, job) -> None:
        z0, z1 = slice_range(self.shape[2], index, job.slices)
        self.smoother.run(self.automaton.state_buffer, job.target["density"], z0, z1)

    def _maps_slice(self, index: int, job) -> None:
        z0, z1 = slice_range(self.shape[2], index, job.slices)
        maps = self._maps[id(job.target)]
        maps.run(job.target["density"], z0, z1)
        if index == job.slices - 1:
            maps.request_max_maps()          # read back when the set is first drawn: no stall here

    def _next_shift(self) -> tuple[int, int]:
        """Whole cells the contents move this step: the wind's drift minus the volume's own motion
        up to the step's placement (the origin when its region slice ran, maybe frames ago)."""
        origin = np.array(self._step_origin)
        moved = origin - self._last_origin
        self._last_origin = origin
        wind = np.asarray(self.settings.weather.wind, float)
        self._drift += wind[[0, 2]] * self.settings.step_seconds - moved[[0, 2]]
        self._blown = self._blown + wind[[0, 2]] * self.settings.step_seconds
        shift = np.trunc(self._drift)
        self._drift -= shift
        limit = max(self.shape) + 1            # larger shifts empty the volume all the same
        return int(np.clip(shift[0], -limit, limit)), int(np.clip(shift[1], -limit, limit))

    def layout(self, base_altitude: float | None = None, cell_size=None, pad: float = 0.0) -> CloudLayout:
        """Where the newest completed set (B) sits in the world (see :class:`CloudSets`): the placement the
        renderer, the ground shadows and the light shafts share. ``base_altitude`` and ``cell_size``
        default to the settings'; ``pad`` widens the column boxes (the sprite radius)."""
        return self.sets().layout(base_altitude, cell_size, pad)

    def _max_maps_of(self, texture_set) -> np.ndarray:
        """The max maps of ``texture_set``, collected from the pixel buffer on first use after its step."""
        maps = self._maps[id(texture_set)]
        if maps.requested:
            self._max_maps[id(texture_set)] = maps.collect_max_maps()
        return self._max_maps[id(texture_set)]

    def sets(self) -> CloudSets:
        """This frame's :class:`CloudSets` (the render graph's imported ``"cloud_sets"``)."""
        a, b, t = self.view()
        self._max_maps_of(a), self._max_maps_of(b)
        here = self.origin.as_tuple()
        return CloudSets(a, b, float(t), self._maps[id(a)], self._maps[id(b)], self._max_maps[id(a)],
                         self._max_maps[id(b)], self._placement.get(id(a), here), self._placement.get(id(b), here),
                         here, self.settings, tuple(self.shape), self._wind_travel(a, b, t), self.drawn)

    def _wind_travel(self, a, b, t: float) -> tuple:
        """(x, z) cells the drawn contents mix(A, B, t) have moved with the wind (the far field follows it)."""
        zero = np.zeros(2)
        travel = (1.0 - t) * self._travel.get(id(a), zero) + t * self._travel.get(id(b), zero)
        return float(travel[0]), float(travel[1])

    def sun_in_cells(self) -> np.ndarray:
        """The sun direction in cell units (what the shear-warp needs when cells are not cubes)."""
        return np.asarray(self.sun(), float) / np.asarray(self.settings.cell_size, float)

    # -- readers -----------------------------------------------------------------------------
    def view(self):
        """(A, B, t): draw mix(A["density"], B["density"], t)."""
        return self.job.view()

    def maps_of(self, texture_set) -> DensityMaps:
        """The density maps computed from ``texture_set``'s density."""
        return self._maps[id(texture_set)]

    def max_maps(self) -> np.ndarray:
        """Elementwise max of the max maps of A and B, shape (1 + bands, gx, gz): a segment whose
        value is 0 is empty in both interpolated steps and may be skipped (7.2.2); A's taken where it
        is drawn (:meth:`CloudSets.max_maps`)."""
        return self.sets().max_maps()

    def cover(self) -> float:
        """Covered fraction of the sky in the newest completed step (B): columns whose summed
        density exceeds ``cover_threshold``. Reads a top-view map back: a diagnostic, not per frame."""
        _, b, _ = self.view()
        sums = self.maps_of(b).read_sums()[0]
        return float((sums > self.settings.cover_threshold).mean())

    def release(self) -> None:
        for obj in (self.region, self.automaton, self.smoother, self.triple, self.shader, self.field,
                    *self._maps.values()):
            if obj is not None:
                obj.release()
        self._maps.clear()
