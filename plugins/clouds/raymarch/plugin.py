"""RaymarchCloudsPlugin: the CloudsPlugin's clouds ray-marched (issue 15), beside the sprites.

Pass "cloud_raymarch" (phase translucent) reads "depth" and "cloud_sets" and composites premultiplied
onto "color" (and onto "cloud_distance" when a media pass wants it, :mod:`atmos.composition`). The
march (``shaders/clouds/raymarch/march.glsl``, one compute invocation per ray in ``march.comp``;
float64 reference :mod:`.reference`) goes through the layer's box with the light of
``clouds/volume/volume.glsl`` (the sprites' model), skips empty sprite groups × height bands
(:func:`skip_map`), stops at ``min_transmittance`` and grows its step with the distance. At
``resolution`` 1 each invocation composites its pixel onto "color" (and "cloud_distance") in place, as
blend_over would. At r > 1 it marches one pixel per r × r block into the low-res storage images
"cloud_raymarch_color" (rgba16f), "cloud_raymarch_distance" (rg32f (a·distance, a)) and
"cloud_raymarch_depth" (r32f: the scene's window depth the ray saw): texel (i, j) is the ray through
the full-res pixel (i·r + o.x, j·r + o.y), o the frame's jitter offset; then :meth:`RaymarchPass._resolve`
(the temporal resolve's hook, wired to :class:`.temporal.TemporalClouds`: with ``reprojection`` its
compute resolve composites the full-res result onto "color" (and "cloud_distance") in place; without,
a depth-aware upsample of this frame's samples is composited instead —
:class:`~atmos.offscreen.OffscreenLayer`' composite).
"""
from __future__ import annotations

import struct
from functools import lru_cache

import moderngl
import numpy as np

from atmos.blue_noise import blue_noise_texture
from atmos.composition import CLOUD_DISTANCE, composition, distance_desc
from atmos.graph import PassBuilder, PassContext, RenderPass, TextureDesc, work_groups
from atmos.plugin import Plugin
from atmos.plugins.clouds.volume.sets import FAR_FIELD
from atmos.plugins.clouds.raymarch.far import far_uniforms
from atmos.plugins.clouds.raymarch.noise import pixel_angle
from atmos.plugins.clouds.raymarch.settings import REFERENCE, SUN_GROWTH, SUN_SPACING, RaymarchCloudSettings
from atmos.plugins.clouds.volume.shape import CloudTypeMap, drawn_shape, march_top, shape_uniforms
from atmos.plugins.clouds.raymarch.temporal import TemporalClouds, jitter, jitter_repeats, jitter_shift
from atmos.gpu import clamp_sampler
from atmos.plugins.clouds.light.ground import GROUND, ground_sun_pass
from atmos.plugins.clouds.volume.binding import bind_volume, unbind_volume
from atmos.plugins.clouds.volume.light import unit_direction
from atmos.offscreen import OffscreenLayer, low_size
from atmos.plugins.clouds.volume.far_link import far_field_link
from atmos.plugins.clouds.volume.field_demand import field_demand
from atmos.plugins.clouds.volume.sets import CLOUD_SETS, CLOUD_VOLUME, CloudSets
from atmos.plugins.clouds.simulation.chain import CloudSimulation
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import bind_textures, write_block, write_uniforms

LOW_COLOR = "cloud_raymarch_color"
LOW_DISTANCE = "cloud_raymarch_distance"
LOW_DEPTH = "cloud_raymarch_depth"
MARCH_BLOCK, MARCH_BINDING = "March", 1        # march.glsl's block of what changes every frame
_MARCH_LAYOUT = struct.Struct("<3ff2i8x")       # its std140 layout (32 bytes)


def type_uniforms(settings) -> dict:
    """shape.glsl's uniforms (:func:`~atmos.plugins.clouds.volume.shape.shape_uniforms`) and how high the
    types' towers reach (:func:`~atmos.plugins.clouds.volume.shape.march_top`)."""
    m = settings.type_map
    typed = m is not None or settings.cloud_type is not None
    top = march_top(None if not typed else (m.highest if m is not None else settings.cloud_type))
    return {**shape_uniforms(settings.cloud_type, m), "march_top": top}


def skip_map(max_maps: np.ndarray) -> np.ndarray:
    """(gz, bands, gx) float32 — texture order of a (gx, bands, gz) 3D texture — from CloudSets'
    max maps (1 + bands, gx, gz): per group × band the max over it and its 26 neighbours, so a 0 means
    the trilinear density (which reads half a cell past a group) is exactly 0 anywhere inside."""
    m = np.asarray(max_maps, np.float32)[1:].transpose(2, 0, 1)          # (gz, bands, gx)
    padded = np.pad(m, 1)
    out = np.zeros_like(m)
    n = m.shape
    for dz in range(3):
        for dy in range(3):
            for dx in range(3):
                np.maximum(out, padded[dz:dz + n[0], dy:dy + n[1], dx:dx + n[2]], out=out)
    return out


@lru_cache(maxsize=16)
def low_descs(size, r: int) -> tuple:
    """The low-res targets' descs (colour, distance, depth the ray saw) at 1/``r`` of ``size``, storage
    images (rgba16f, rg32f, r32f), made once per size (setups run every frame)."""
    low = low_size(size, r)
    return (TextureDesc(low, components=4, dtype="f2", filter="nearest", storage=True), distance_desc(low),
            TextureDesc(low, components=1, dtype="f4", filter="nearest", storage=True))


def sample_offset(frame_index: int, r: int) -> tuple[int, int]:
    """The jitter offset o of a frame: the temporal resolve's sequence (all r² offsets every r² frames)."""
    return jitter(frame_index, r)


class RaymarchCloudsPlugin(Plugin):
    """Ray-marched clouds of the CloudsPlugin's "cloud_sets" (no CloudRenderPlugin needed; a scene uses
    one renderer or the other): ``RaymarchCloudsPlugin(settings=None, **fields)`` with
    :class:`RaymarchCloudSettings`; ``configure(**changes)`` changes any of them live."""

    settings_class = RaymarchCloudSettings

    def __init__(self, settings: RaymarchCloudSettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.gpu = self.composition = self.link = self.demand = self.shape = self.pass_ = None
        self.simulated = False

    @classmethod
    def reference(cls, **fields) -> "RaymarchCloudsPlugin":
        """The march in the reference configuration (:data:`.settings.REFERENCE`: full resolution,
        uniform quarter-cell midpoint steps, no noise, jitter, history or early exit); ``fields``
        change any setting (e.g. ``step=0.1``, ``enabled=False``, ``base_altitude``)."""
        return cls(**{**REFERENCE, **fields})

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("RaymarchCloudsPlugin needs an App with a GPU context (App(gpu))")
        self.gpu = app.gpu
        self.composition = composition(app)
        self.composition.writers.add(RaymarchPass.name)     # the fog gets the clouds' own distance,
        self.composition.covers[RaymarchPass.name] = self.runs     # every pixel of it (the first writer: no clear)
        self.pass_ = RaymarchPass(self)
        app.graph.add_pass(self.pass_)
        ground_sun_pass(app.graph)
        self.demand = field_demand(app)
        self.demand.readers.add(self)
        self.shape = drawn_shape(app)
        self.shape.source = self.drawn_type        # the columns' readers shape their shadows like the march
        self.link = far_field_link(app)
        self.link.marchers.add(self)    # a far field's 2D pass steps aside while this marches it

    def finish(self, app) -> None:
        self.simulated = app.get_resource(CloudSimulation) is not None     # weather-driven, not static
        # far field only (volume False): drawn behind the volume's renderers (their exclusive group)
        self.pass_.behind = tuple(p.name for p in app.graph.passes
                                  if p.phase == RaymarchPass.phase and p.exclusive == CLOUD_VOLUME and p is not self.pass_)

    def runs(self) -> bool:
        """Whether the march draws this frame (``enabled``, and the volume or the far field to march):
        then it writes every pixel of its outputs."""
        s = self.settings
        return bool(s.enabled and (s.volume or self.marches_far_field()))

    def marches_far_field(self) -> bool:
        """Whether the march goes on through the volumetric far field (``far_field`` on, enabled, and a
        CloudFarFieldPlugin, whose cover it uses, in the scene and enabled)."""
        s = self.settings
        return bool(s.enabled and s.far_field and self.link is not None and self.link.present())

    def drawn_type(self):
        """(shape.glsl's uniforms, the type map's texture or None) while the march draws with a cloud type,
        else None (:class:`~atmos.plugins.clouds.volume.shape.DrawnShape`)."""
        s = self.settings
        if not (s.enabled and s.volume) or self.pass_ is None or (s.cloud_type is None and s.type_map is None):
            return None
        return s.cloud_type, s.type_map, self.pass_._type_texture(s.type_map) if s.type_map is not None else None

    def cleanup(self, app) -> None:
        if self.shape is not None and self.shape.source == self.drawn_type:
            self.shape.source = None
        if self.demand is not None:
            self.demand.readers.discard(self)
        if self.composition is not None:
            self.composition.writers.discard(RaymarchPass.name)
            self.composition.covers.pop(RaymarchPass.name, None)
        if self.link is not None:
            self.link.marchers.discard(self)
            self.link = None

    def sigma_t(self, sim: CloudSets) -> float:
        """Extinction in 1/m at density 1: the medium's."""
        return float(sim.settings.sigma_t)

    def wind(self, sim: CloudSets) -> tuple:
        """m/s the detail noise scrolls with: the weather's wind (cells/s × cell size) for simulated
        clouds, else (static ``CloudsPlugin(density=...)``) the ``wind`` setting."""
        if not self.simulated:
            return tuple(self.settings.wind)
        return tuple(float(w) * float(c) for w, c in zip(sim.settings.weather.wind, sim.settings.cell_size))


class RaymarchPass(RenderPass):
    """Pass "cloud_raymarch"; see the module docstring. ``enabled`` False: declares nothing (culled).
    ``volume`` False: the far field alone, before the volume's renderers and not their alternative."""
    name = "cloud_raymarch"
    phase = "translucent"
    behind: tuple = ()                      # the volume's renderers' passes (RaymarchCloudsPlugin.finish)

    @property
    def exclusive(self) -> str:
        """Never on beside the sprites while it draws the volume (a GraphError names both)."""
        return CLOUD_VOLUME if self.plugin.settings.volume else ""

    @property
    def before(self) -> tuple:
        """The far field alone is drawn behind the volume's renderers."""
        return () if self.plugin.settings.volume else self.behind

    def __init__(self, plugin: RaymarchCloudsPlugin):
        self.plugin = plugin
        self.gpu = self.sampler = self.offscreen = self.skip = self.temporal = self.noise = self.jitter = None
        self._skip_key = None
        self._types = None                  # (the CloudTypeMap, its texture)
        self._typed = (None, None)          # (the settings, their type_uniforms): worked out once per change
        self.frame_index = 0

    def setup_key(self) -> tuple:
        plugin = self.plugin
        comp = plugin.composition
        return (plugin.settings, plugin.marches_far_field(), comp.distance, comp.distance_first, plugin.gpu.size)

    def first_distance(self) -> bool:
        """Whether this pass makes "cloud_distance" (its first writer, :attr:`Composition.distance_first`)."""
        return self.plugin.composition.distance_first == self.name

    def setup(self, builder: PassBuilder) -> None:
        s = self.plugin.settings
        if not self.plugin.runs():
            return                          # off, or the far field alone with none to march
        builder.read(DEPTH)
        builder.read(CLOUD_SETS)
        builder.read(GROUND, access="uniform")
        if self.plugin.marches_far_field():
            builder.read(FAR_FIELD)
        # composited onto in place: by the march (resolution 1), the temporal resolve or the upsample
        builder.read(COLOR, access="storage")
        builder.write(COLOR, access="storage")
        if self.first_distance():           # every pixel stored: nothing cleared before
            builder.create(CLOUD_DISTANCE, distance_desc(tuple(self.plugin.gpu.size)), access="storage")
        elif self.plugin.composition.distance:
            builder.read(CLOUD_DISTANCE, access="storage")
            builder.write(CLOUD_DISTANCE, access="storage")
        if s.resolution > 1:
            descs = low_descs(tuple(self.plugin.gpu.size), s.resolution)
            for name, desc in zip((LOW_COLOR, LOW_DISTANCE, LOW_DEPTH), descs):
                builder.create(name, desc, access="storage")

    def prepare(self, gpu) -> None:
        self.gpu = gpu
        self.sampler = clamp_sampler(gpu.ctx)
        self.offscreen = OffscreenLayer(gpu, LOW_COLOR, LOW_DEPTH, LOW_DISTANCE)
        self.temporal = TemporalClouds(gpu)

    def program(self, far: bool = False):
        """The variant for the detail octaves, sun steps and far field, into the low-res targets or, at
        resolution 1, onto "color" (and "cloud_distance" when declared) in place (the program cache: a
        dict lookup)."""
        s = self.plugin.settings
        onto = s.resolution == 1
        distance = (2 if self.first_distance() else 1) if onto and self.plugin.composition.distance else 0
        return self.gpu.program(compute_shader="clouds/raymarch/march.comp",
                                defines={"DETAIL_OCTAVES": s.detail_octaves,
                                         "SUN_STEPS": s.sun_steps,
                                         "FAR_FIELD": int(far),
                                         "MARCH_VOLUME": int(s.volume),
                                         "MARCH_ONTO": int(onto),
                                         "MARCH_DISTANCE": distance})

    def _skip_texture(self, sim: CloudSets):
        """The dilated skip map as a small r32f 3D texture, re-uploaded when the max maps change."""
        key = (sim.max_a, sim.max_b, sim.a_shift)      # held, so a new array is never taken for an old one
        old = self._skip_key
        if old is None or old[0] is not key[0] or old[1] is not key[1] or old[2] != key[2]:
            data = skip_map(sim.max_maps())
            size = (data.shape[2], data.shape[1], data.shape[0])
            if self.skip is None or self.skip.size != size:
                if self.skip is not None:
                    self.skip.release()
                self.skip = self.gpu.ctx.texture3d(size, 1, dtype="f4")
                self.skip.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.skip.write(np.ascontiguousarray(data).tobytes())
            self._skip_key = key
        return self.skip

    def _type_texture(self, type_map: CloudTypeMap):
        """The map's types as an R32F texture (linear, clamped to the edge), uploaded when the map changes."""
        if self._types is None or self._types[0] is not type_map:
            self._release_types()
            nz, nx = type_map.types.shape
            tex = self.plugin.gpu.ctx.texture((nx, nz), 1, type_map.types.tobytes(), dtype="f4")   # (any pass may ask first)
            tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
            tex.repeat_x = tex.repeat_y = False
            self._types = (type_map, tex)
        return self._types[1]

    def _release_types(self) -> None:
        if self._types is not None:
            self._types[1].release()
            self._types = None

    def _uniforms(self, frame: PassContext, sim: CloudSets, layout) -> dict:
        s, view = self.plugin.settings, frame.view
        cell = np.asarray(layout.cell, np.float64)
        maps = sim.maps_of(sim.view()[0])
        skip_cells = (float(layout.group[0]), float(maps.band_height), float(layout.group[1]))
        grid = (layout.grid[0], -(-layout.shape[1] // maps.band_height), layout.grid[1])
        return {"layer_min": tuple(layout.lo.tolist()), "layer_max": tuple(layout.hi.tolist()),
                "cell_size": tuple(cell.tolist()), "sigma_t": self.plugin.sigma_t(sim),
                "steps": s.steps, "step_base": float(s.step * min(cell)), "step_growth": s.step_growth,
                "min_transmittance": s.min_transmittance, "skipping": int(s.empty_space_skipping),
                "skip_cells": skip_cells, "max_skips": int(sum(grid)) + 3, "factor": s.resolution,
                "frame_size": tuple(map(int, view.size)), "jittered": int(s.jitter), "sun_growth": SUN_GROWTH,
                "pixel_angle": pixel_angle(view), **self._type_uniforms(s)}

    def _type_uniforms(self, s: RaymarchCloudSettings) -> dict:
        if self._typed[0] is not s:
            self._typed = (s, type_uniforms(s))
        return self._typed[1]

    def _march_block(self, frame: PassContext, cell, offset) -> bytes:
        """march.glsl's March block: the sun march's first step, the jitter's turn (per frame only where
        the resolve averages: r > 1 with reprojection) and the pixel marched in each r × r block."""
        s = self.plugin.settings
        sun = unit_direction(frame.view.sun) * (SUN_SPACING * float(min(cell)))
        shift = jitter_shift(self.frame_index, s.resolution) if s.resolution > 1 and s.reprojection else 0.0
        return _MARCH_LAYOUT.pack(*sun.tolist(), shift, int(offset[0]), int(offset[1]))

    def execute(self, frame: PassContext) -> None:
        s, view = self.plugin.settings, frame.view
        sim: CloudSets = frame.resource(CLOUD_SETS)
        r = s.resolution
        offset = sample_offset(self.frame_index, r) if r > 1 else (0, 0)
        distance = frame.declares(CLOUD_DISTANCE)
        far = frame.declares(FAR_FIELD)
        if far:                             # first: the layer's measure dispatches programs of its own
            frame.resource(FAR_FIELD).prepare(view, sim)
        p = self.program(far)
        layout = sim.layout(s.base_altitude)
        uniforms = self._uniforms(frame, sim, layout)
        write_uniforms(p, uniforms)
        write_block(p, MARCH_BLOCK, MARCH_BINDING, self._march_block(frame, layout.cell, offset))
        bind_volume(p, sim, self.sampler, view.sun, s.octaves, s.ms_diffusion, layout.heights, view.ground,
                    ground_light=frame.resource(GROUND), span=uniforms["march_top"])   # towers' sun too
        if s.type_map is not None:
            bind_textures(p, cloud_type_map=self._type_texture(s.type_map))
        else:
            self._release_types()
        if s.empty_space_skipping:
            bind_textures(p, skip_map=self._skip_texture(sim))
        else:                               # nothing uploaded; the shader reads no skip map
            self._release_skip()
        bind_textures(p, scene_depth=frame.resource(DEPTH))
        if s.jitter:
            if self.jitter is None:
                self.jitter = blue_noise_texture(self.gpu.ctx)
            bind_textures(p, blue_noise=self.jitter)
        if far:
            self._bind_far(frame, p, sim)
        if s.detail_octaves:
            layout = sim.layout(s.base_altitude)
            self._detail().bind(p, view.time, self.plugin.wind(sim), s.detail_scale * float(min(layout.cell)),
                                s.detail_strength, layer=(float(layout.lo[1]), float(layout.hi[1] - layout.lo[1])))
        if r == 1:                          # straight onto the frame
            images = {"color_image": COLOR, **({"distance_image": CLOUD_DISTANCE} if distance else {})}
        else:                               # every texel is written: no clear
            images = {"color_image": LOW_COLOR, "distance_image": LOW_DISTANCE, "depth_image": LOW_DEPTH}
        try:
            frame.dispatch(p, work_groups(frame.image(images["color_image"]).size, (8, 8)), images=images)
        finally:
            unbind_volume(p, self.sampler)
        if r > 1:
            self._resolve(frame, LOW_COLOR, LOW_DISTANCE, offset)
        else:
            self.temporal.release()         # no history at full resolution
        self.frame_index += 1

    def _bind_far(self, frame: PassContext, p, sim: CloudSets) -> None:
        """The far field's textures, cover and uniforms (field.glsl, far.glsl) for this frame."""
        view, s = frame.view, self.plugin.settings
        layer = frame.resource(FAR_FIELD)         # prepared in execute
        layer.use(p, view, sim)
        write_uniforms(p, far_uniforms(s, layer.settings, sim.layout(s.base_altitude), view, layer.tile_size))

    def _detail(self):
        """The context's detail noise (built on first use, then held: no lookup per frame)."""
        if self.noise is None:
            from atmos.plugins.clouds.raymarch.noise import DetailNoise
            self.noise = DetailNoise(self.gpu)
        return self.noise

    def _resolve(self, frame: PassContext, low_color: str, low_distance: str, offset) -> None:
        """The temporal resolve's hook: composite this frame's low-res samples onto "color" (and
        "cloud_distance") in place, premultiplied. ``reprojection`` on: :class:`.temporal.TemporalClouds`
        resolves them with its history in one compute dispatch that also composites the result. Off: the
        history is dropped and a depth-aware upsample of this frame's samples is composited instead."""
        view, s = frame.view, self.plugin.settings
        camera = view.camera
        distance = frame.declares(CLOUD_DISTANCE)
        if s.reprojection:
            self.temporal.resolve(frame.resource(low_color), frame.resource(low_distance), view.size,
                                  s.resolution, offset, camera, view.aspect,
                                  depth=frame.resource(DEPTH), history_clamp=s.history_clamp,
                                  motion_limit=s.motion_limit, low_depth=frame.resource(LOW_DEPTH),
                                  onto=frame.resource(COLOR),
                                  onto_distance=frame.resource(CLOUD_DISTANCE) if distance else None,
                                  repeats=not s.jitter or jitter_repeats(self.frame_index, s.resolution),
                                  store_distance=distance and self.first_distance())
            return
        self.temporal.release()
        self.offscreen.end(frame, s.resolution, camera.near, camera.far, distance, offset=offset,
                           first=distance and self.first_distance())

    def _release_skip(self) -> None:
        if self.skip is not None:
            self.skip.release()
        self.skip = self._skip_key = None

    def release(self) -> None:
        if self.temporal is not None:
            self.temporal.release()
        if self.sampler is not None:
            self.sampler.release()
        self.sampler = self.noise = None     # the noise textures belong to the context's cache
        self._release_skip()
        self._release_types()
        if self.jitter is not None:
            self.jitter.release()
            self.jitter = None
