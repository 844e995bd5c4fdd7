"""FarFieldLayer: the far field's textures and cover for one frame, shared by every pass that needs it.

The far field's clouds are a function of world (x, z): the four octave textures, each at its own
turned uv (:mod:`.pattern`, drift included), each point taking the volume's column sum at its rank
(:mod:`.cover`). The tile they are drawn at, :attr:`FarFieldLayer.tile_size`, is the setting's or
(None) sized so that their cover changes per metre as often as the volume's (:meth:`update_tile`, from a
measure read back once per simulation step, a step after it was taken: no frame waits for it). The far-field
pass draws them; the ground shadows (:mod:`atmos.plugins.clouds.shadows`) darken the ground under them
with the same function (``shaders/clouds/far_field/field.glsl``). The plugin imports this object as the
graph resource ``"far_field"``; each pass that uses it calls :meth:`prepare` (re-bakes the octaves
when the sun turned, measures each shown set's cover once per simulation step and mixes the two for the
frame: :class:`RankMeasure`) and :meth:`use`. The same measure gives the volume's vertical
shape by rank (:attr:`FarFieldLayer.profile`, :meth:`read_profile`), which the ray march's volumetric
far field takes its density from; a second dispatch its light by rank (:attr:`FarFieldLayer.light`,
:mod:`.rank_light`), which both far fields light their columns with.
"""
from __future__ import annotations

from dataclasses import replace
from operator import is_

import moderngl
import numpy as np

from atmos.plugins.clouds.far_field.columns import INTERVALS, rank_texture, read_rank_texture, use_columns
from atmos.plugins.clouds.far_field.cover import LEVELS, QUANTILES, level_ranks, matched_tile_size, pattern_crossings
from atmos.plugins.clouds.far_field.pattern import CHANNEL_STEPS, PERIODS, octave_frequencies, octave_offsets, rotations, turns_bytes
from atmos.plugins.clouds.far_field.rank_light import FIELD_BINS, RankLight
from atmos.plugins.clouds.light.medium import octave_parameters
from atmos.plugins.clouds.volume.light import cell_tau, unit_direction
from atmos.plugins.clouds.volume.sets import CloudSets
from atmos.tile_octaves import OctaveTextures
from atmos.gpu.uniforms import bind_buffers, bind_images, bind_textures, write_uniforms
from atmos.gpu.hazards import dispatch

REBAKE_TOLERANCE = 0.05          # re-bake the octaves when the sun moved the light step by this fraction
MAX_HEIGHTS = 64                 # cover.comp's most height samples
HISTOGRAM_BINS = 256             # cover.comp's BINS (plus one for the empty columns)
COLUMNS_PER_GROUP = 1024         # the cover's measure: columns per group of 256 (four each) ...
MAX_GROUPS = 256                 # ... in at most this many groups (their partials summed by one)
TILE_TIME = 5.0                  # s: the matched tile follows a change of the volume's with this time constant


def profile_heights(layers: int) -> int:
    """Height samples of the measured profile: the layer's height in cells, at most MAX_HEIGHTS."""
    return max(1, min(int(layers), MAX_HEIGHTS))


def travel(settings, sets: CloudSets, time: float) -> np.ndarray:
    """(2,) metres the pattern has drifted. ``settings.wind`` None: the distance the simulated clouds
    have moved with their wind (``CloudSets.wind_travel``, cells × cell size), so both move together;
    a tuple: that (x, z) drift in m/s with the App clock ``time``."""
    if settings.wind is None:
        return np.asarray(sets.wind_travel, np.float64) * np.asarray(sets.settings.cell_size, np.float64)[[0, 2]]
    return np.asarray(settings.wind, np.float64) * float(time)


def drift(settings, sets: CloudSets, time: float, tile_size: float) -> np.ndarray:
    """(4, 2) each octave's drift in its own uv (turned, its period: :mod:`.pattern`), wrapped to [0, 1):
    the same world travel (:func:`travel`) for every octave, with the layer's tile ``tile_size`` (m,
    FarFieldLayer.tile_size)."""
    return octave_offsets(travel(settings, sets, time), tile_size)


def column_tau(settings, sets: CloudSets) -> float:
    """field.glsl's field_column_tau: optical depth per cell of a column sum, ``thickness · sigma_t ·
    cell height`` (the column far.comp draws and the ground shadows take beyond the volume)."""
    return float(settings.thickness) * cell_tau(sets.settings)


def rank_table_texture(gpu, table):
    """field.glsl's far_rank_table: ``table`` (LEVELS, columns) (:func:`.cover.rank_table`) as an R32F
    texture, linear, clamped to the edge (fbm beyond the table: rank 0 or 1)."""
    table = np.asarray(table, np.float64)
    if table.shape[0] != LEVELS:
        raise ValueError(f"rank_table_texture: {table.shape[0]} rows, field.glsl reads FIELD_LEVELS = {LEVELS}")
    texture = gpu.track(gpu.ctx.texture(table.shape[::-1], 1, np.ascontiguousarray(table, "f4").tobytes(), dtype="f4"))
    texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
    texture.repeat_x = texture.repeat_y = False
    return texture


class RankMeasure:
    """One measure of the far field's inputs (GL objects of one GpuContext): ``cover`` (float32: cover,
    QUANTILES column-sum quantiles, transitions: cover.comp's Cover), ``profile`` (the volume's shape by
    rank, rg32f, or None) and ``light`` (:class:`.rank_light.RankLight`); ``of``: what it was taken of
    (a set, its version and the settings it was taken with), None when it holds no step's measure."""

    def __init__(self, gpu):
        self.gpu = gpu
        self.cover = gpu.track(gpu.ctx.buffer(reserve=4 * (2 + QUANTILES)))
        self.profile = None
        self._rows = 0                       # the profile's rows (its height samples)
        self.light = RankLight(gpu)
        self.of = None

    def profile_texture(self, heights: int):
        """:attr:`profile`, made (again) with ``heights`` rows."""
        if self.profile is None or self._rows != heights:
            if self.profile is not None:
                self.profile.release()
            self.profile, self._rows = rank_texture(self.gpu, heights, 2), heights
        return self.profile

    def release(self) -> None:
        for obj in (self.cover, self.profile, self.light):
            if obj is not None:
                obj.release()
        self.cover = self.profile = self.light = self.of = None


class FarFieldLayer:
    """The octave textures and the measured cover of the far field (GL objects of one GpuContext).

    The measure is taken once per simulation step: of each shown set alone (A's kept from the step it
    was B), into one of two :class:`RankMeasure`; each frame one dispatch mixes the two at the frame's
    t into the frame's own (``shaders/clouds/far_field/rank_mix.comp``), which every pass reads."""

    def __init__(self, gpu, plugin):
        self.gpu, self.plugin = gpu, plugin
        self.octaves = OctaveTextures(gpu)
        self.frame = RankMeasure(gpu)        # the frame's measure: what the far fields, shadows and shafts read
        self._steps = (RankMeasure(gpu), RankMeasure(gpu))     # the shown sets' own, one step each
        self._staged = gpu.track(gpu.ctx.buffer(reserve=self.frame.cover.size))   # a copy of one step's measure
        self._staged_for = None              # the set B whose measure is staged (held: never a reused id)
        self._measure = None                 # [partials, histogram, profile sums]: the measure's own buffers
        self._target = None                  # the matched tile the drawn one follows (m)
        self.tile_size = float(self.plugin.settings.tile_size or 8000.0)    # metres per tile as drawn (update_tile)
        self._tile_time = None               # App time of the last update_tile
        self._matched = False                # tile_size follows a measure (else the first one sets it)
        self._prepared = None                # the SceneView of the frame prepared last (held: never a reused id)
        self._uniforms = None                # (view, sim, tile size, settings) and the field uniforms for them
        self.ranks = None                    # far_rank_table (rank_table_texture) of the texture setting _ranks_for
        self._ranks_for = None

    @property
    def settings(self):
        return self.plugin.settings

    @property
    def cover(self):
        """The frame's cover buffer (float32: cover, QUANTILES column-sum quantiles, transitions)."""
        return self.frame.cover

    @property
    def profile(self):
        """(INTERVALS, heights) rg32f: the volume's shape by rank (cover.comp), None until measured."""
        return self.frame.profile

    @property
    def light(self) -> RankLight:
        """The volume's light by rank (light_by_rank.comp), as mixed for the frame."""
        return self.frame.light

    def prepare(self, view, sim: CloudSets) -> None:
        """Bake (when needed), measure the shown sets (once per simulation step) and mix their measures
        for the frame (small dispatches), once per frame: every user (the far-field pass or the march,
        the shadows, the shafts) calls it, the first one does it. The volume's shape by rank is measured
        while the ray march draws the far field, its light while a far field is drawn (not just shadows).
        A user calls it before binding anything of its own: it dispatches programs of its own."""
        if view is self._prepared:
            return
        self._prepared = view
        params = self.plugin.settings
        sun_dir = tuple(map(float, unit_direction(view.sun)))     # light_uniforms' sun_dir
        if self.octaves.needs_bake(params, sun_dir, REBAKE_TOLERANCE):
            self.octaves.bake(params, sun_dir, octave_frequencies(params.base_frequency), rotations(), CHANNEL_STEPS)
        profile = self.plugin.drawn_by_march()
        light = self.plugin.light_settings() if profile or params.enabled else None
        heights = profile_heights(sim.shape[1])
        a, b = self._step_measures(sim, profile, light, heights)
        self._mix(float(sim.t), a, b, profile, light is not None, heights)
        self.update_tile(sim, float(view.time))

    def _step_measures(self, sim: CloudSets, profile: bool, light, heights: int) -> tuple[RankMeasure, RankMeasure]:
        """The measures of A alone and of B alone, each taken when first shown (B's kept for when it is A;
        a static set, shown as both, measured once); ``light``: the light settings, None for no light."""
        key = (profile, light, sim.settings, tuple(sim.shape))
        shown = ((sim.a, sim.maps_a, sim.placement_a), (sim.b, sim.maps_b, sim.placement_b))[:1 if sim.b is sim.a else 2]
        found = [next((m for m in self._steps if m.of is not None and m.of[0] is s and m.of[1] == s.version
                       and m.of[2] == key), None) for s, _, _ in shown]
        for i, (s, maps, placement) in enumerate(shown):
            if found[i] is not None:
                continue
            m = found[i] = next(m for m in self._steps if m not in found)     # not the other set's kept one
            alone = replace(sim, a=s, b=s, t=1.0, maps_a=maps, maps_b=maps, placement_a=placement, placement_b=placement)
            self.measure_cover(alone, profile, into=m)
            if light is not None:
                m.light.measure(alone, m.cover, octave_parameters(light.octaves, sim.settings)[0], heights)
            m.of = (s, s.version, key)
        return found[0], found[-1]

    def _mix(self, t: float, a: RankMeasure, b: RankMeasure, profile: bool, light: bool, heights: int) -> None:
        """The frame's measure: ``a`` and ``b`` (taken at ``heights`` samples per column) mixed at ``t``
        (rank_mix.comp, one dispatch)."""
        field = light and a.light.has_field and b.light.has_field
        c = self.gpu.program(compute_shader="clouds/far_field/rank_mix.comp",
                             defines={"PROFILE": int(profile), "LIGHT": int(light), "FIELD": int(field)})
        rows = 2                              # the cover buffer's 35 floats: two rows of 32 invocations
        textures, images = {}, {}
        if profile:
            textures.update(profile_a=a.profile, profile_b=b.profile)
            images["column_profile"] = self.frame.profile_texture(heights)
            rows = max(rows, heights)
        if light:
            out, la, lb = self.frame.light, a.light, b.light
            out.has_field = field
            bins = min(heights, FIELD_BINS)
            out.allocate(bins)
            textures.update(sun_a=la.sun, sun_b=lb.sun, thickness_a=la.thickness, thickness_b=lb.thickness,
                            height_a=la.height, height_b=lb.height, sun_profile_a=la.sun_profile,
                            sun_profile_b=lb.sun_profile)
            images.update(sun_by_rank=out.sun, thickness_by_rank=out.thickness, height_by_rank=out.height,
                          sun_profile=out.sun_profile)
            if field:
                textures.update(field_a=la.field, field_b=lb.field, field_profile_a=la.field_profile,
                                field_profile_b=lb.field_profile)
                images.update(field_column=out.field, field_profile=out.field_profile)
            rows = max(rows, bins)
        if textures:
            bind_textures(c, textures)
        if images:
            bind_images(c, images)
        bind_buffers(c, Cover=self.frame.cover, CoverA=a.cover, CoverB=b.cover)
        write_uniforms(c, t=t)
        dispatch(c, 1, -(-rows // 4))

    def update_tile(self, sim: CloudSets, time: float) -> None:
        """:attr:`tile_size` from the last measure: ``settings.tile_size`` when set, else the tile at which
        the far field's cover changes along a line as often per metre as the volume's (cover.comp's
        transitions per cell / the cell size; :func:`.cover.matched_tile_size`; :meth:`_step_measure`),
        followed with the time constant TILE_TIME (the pattern zooms slowly, never jumps; a first measure
        is taken at once)."""
        params = self.plugin.settings
        dt = time - self._tile_time if self._tile_time is not None else 0.0
        self._tile_time = time
        if params.tile_size is not None:
            self._matched = False
            self.tile_size = float(params.tile_size)
            return
        measured = self._step_measure(sim)
        if measured is not None:
            cover, transitions = measured
            cell = float(np.mean(np.asarray(sim.settings.cell_size, np.float64)[[0, 2]]))
            self._target = matched_tile_size(pattern_crossings(params.base_frequency, params.seed, params.size),
                                             cover, transitions / cell)
        if self._target is None:
            return
        k = min(1.0, max(dt, 0.0) / TILE_TIME) if self._matched else 1.0
        self.tile_size *= (self._target / self.tile_size) ** k
        self._matched = True

    def _step_measure(self, sim: CloudSets) -> tuple[float, float] | None:
        """(cover, transitions per cell) once per simulation step, else None: when a step's sets are first
        drawn, the staged copy of the last step's measure is read (frames old: no wait) and this frame's
        is copied on the GPU into its place. The very first measure is read at once (start-up)."""
        if sim.b is self._staged_for:
            return None
        first = self._staged_for is None
        measured = None if first else _transitions(self._staged)
        self.gpu.hazards.use(reads=[(self.cover, "copy")], writes=[(self._staged, "copy")])
        self.gpu.ctx.copy_buffer(self._staged, self.cover)
        self._staged_for = sim.b
        return _transitions(self._staged) if first else measured

    def measure_cover(self, sim: CloudSets, profile: bool | None = None, into: RankMeasure | None = None) -> None:
        """The simulation's edge-weighted cover and column-sum quantiles into the buffer the shaders
        read (float32: cover, then QUANTILES column sums in cells; :meth:`read_cover`), and with
        ``profile`` (None: when the ray march draws the far field, ``drawn_by_march()``; it reads the
        sets' density) the covered columns' vertical profile per rank interval into :attr:`profile`
        (:meth:`read_profile`). Many groups measure the columns, one sums them (cover.comp's passes).
        ``into``: the :class:`RankMeasure` written (default: the frame's, :attr:`frame`)."""
        profile = self.plugin.drawn_by_march() if profile is None else bool(profile)
        into = self.frame if into is None else into
        columns = int(sim.shape[0]) * int(sim.shape[2])
        groups = max(1, min(MAX_GROUPS, -(-columns // COLUMNS_PER_GROUP)))
        if self._measure is None:       # zero-filled; the passes that read the sums zero them again
            self._measure = [self.gpu.track(self.gpu.ctx.buffer(bytes(size)))
                             for size in (16 * MAX_GROUPS, 4 * (HISTOGRAM_BINS + 1), 4 * INTERVALS * MAX_HEIGHTS)]
        partials, histogram, acc = self._measure
        c = self.gpu.program(compute_shader="clouds/far_field/cover_columns.comp")
        use_columns(c, sim, density=False)
        write_uniforms(c, threshold=float(sim.settings.cover_threshold), max_sum=float(sim.shape[1]))
        bind_buffers(c, CoverPartials=partials, CoverHistogram=histogram)
        dispatch(c, groups)
        c = self.gpu.program(compute_shader="clouds/far_field/cover.comp")
        write_uniforms(c, groups=groups, max_sum=float(sim.shape[1]))
        bind_buffers(c, Cover=into.cover, CoverPartials=partials, CoverHistogram=histogram)
        dispatch(c, 1)
        if not profile:
            return
        heights = profile_heights(sim.shape[1])
        c = self.gpu.program(compute_shader="clouds/far_field/cover_profile.comp")
        use_columns(c, sim, density=True)
        write_uniforms(c, heights=heights)
        bind_buffers(c, Cover=into.cover, CoverProfile=acc)
        dispatch(c, groups)
        c = self.gpu.program(compute_shader="clouds/far_field/cover_profile_finish.comp")
        write_uniforms(c, heights=heights, layer_rows=int(sim.shape[1]))
        bind_buffers(c, CoverProfile=acc)
        bind_images(c, column_profile=into.profile_texture(heights))
        dispatch(c, 1)

    def read_profile(self) -> np.ndarray:
        """(INTERVALS, heights, 2) as last measured: [k, j] = (density per unit column sum, share of the
        column above) of rank interval k at height sample j (a GPU → CPU copy: tests and tools)."""
        if self.profile is None:
            raise RuntimeError("FarFieldLayer.read_profile: no profile measured yet; it is measured while a ray "
                               "march draws the far field, or by measure_cover(sim, profile=True)")
        return read_rank_texture(self.profile)

    def read_cover(self) -> tuple[float, np.ndarray]:
        """(cover, (QUANTILES,) column-sum quantiles) as last measured (a GPU → CPU copy: tests and tools)."""
        values = np.frombuffer(self.cover.read(), np.float32).astype(np.float64)
        return float(values[0]), values[1:1 + QUANTILES]

    def read_transitions(self) -> tuple[float, float]:
        """(cover, the cover's transitions per cell along a line) as last measured (a GPU → CPU copy: tests
        and tools)."""
        return _transitions(self.cover)

    def use(self, program, view, sim: CloudSets) -> None:
        """Bind field.glsl's textures and cover and set its uniforms."""
        params = self.plugin.settings
        self.octaves.bind(program)
        bind_buffers(program, Cover=self.cover)
        if self.profile is not None:
            bind_textures(program, far_profile=self.profile)
        self.light.use(program)
        key = (view, sim, self.tile_size, params)
        cached = self._uniforms
        if cached is None or len(cached[0]) != len(key) or not all(map(is_, cached[0], key)):
            cached = self._uniforms = (key, self._field_uniforms(view, sim))   # once per frame, whatever the users
        bind_textures(program, far_rank_table=self.ranks)
        write_uniforms(program, cached[1])

    def _field_uniforms(self, view, sim: CloudSets) -> dict:
        """field.glsl's uniforms for ``view`` (what :meth:`use` writes)."""
        params = self.plugin.settings
        time = float(view.time) if params.animate else 0.0
        layout = sim.layout()
        camera = np.asarray(view.camera.position, np.float64)
        offsets = octave_offsets(camera[[0, 2]] + travel(params, sim, time), self.tile_size)
        span, first = self._rank_table()
        crossings = pattern_crossings(params.base_frequency, params.seed, params.size)   # far.comp's slant_rank
        return dict(field_origin=tuple(camera[[0, 2]]), field_tile_size=float(self.tile_size),
                    field_lod_shift=tuple(np.log2(PERIODS)),
                    field_mid_height=float(0.5 * (layout.lo[1] + layout.hi[1])),
                    field_column_tau=column_tau(params, sim),
                    field_offsets=offsets.astype("f4").tobytes(),
                    field_turns=turns_bytes(),   # column-major
                    far_rank_span=tuple(span), field_first_level=first,
                    field_crossings=np.asarray(crossings, "f4").tobytes())

    def _rank_table(self) -> tuple:
        """(span, first level) of :attr:`ranks`, baked anew when the texture setting changed."""
        params = self.plugin.settings
        key = (int(params.base_frequency), int(params.seed), int(params.size))
        table, span, first = level_ranks(*key)
        if key != self._ranks_for:
            if self.ranks is not None:
                self.ranks.release()
            self.ranks, self._ranks_for = rank_table_texture(self.gpu, table), key
        return span, first

    def release(self) -> None:
        if self.octaves is not None:
            self.octaves.release()
            self.octaves = None
        for buffer in (self._staged, *(self._measure or ())):
            if buffer is not None:
                buffer.release()
        self._staged = self._staged_for = self._measure = None
        for measure in (self.frame, *self._steps):
            measure.release()
        if self.ranks is not None:
            self.ranks.release()
            self.ranks = self._ranks_for = None


def _transitions(buffer) -> tuple[float, float]:
    """(cover, transitions per cell) of a cover.comp measure in ``buffer``."""
    values = np.frombuffer(buffer.read(), np.float32).astype(np.float64)
    return float(values[0]), float(values[1 + QUANTILES])
