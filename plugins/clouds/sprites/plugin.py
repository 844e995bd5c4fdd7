"""CloudRenderPlugin: the CloudSimulation's clouds as point sprites (thesis ch. 6, 7.2).

Drawing: the segments a frame draws (group x, slice or block y, group z, level and span; see
``segments``) go, back to front, into an instance buffer, and the whole layer is ONE multi-draw with
no vertex buffer: gl_VertexID is a block's place in its unit (a group, or 2 beside a boundary the
camera stands on), walked farther neighbour first from where the camera stands (blending is in
vertex order, so the back-to-front order holds inside a unit too). The vertex shader fetches
density and transmittance as mix(A, B, t), throws empty cells out of the view volume, sizes the
sprite from distance and density, and lights it (the source J of :mod:`atmos.plugins.clouds.light.medium`: octave
weights of the sun's transmittance, sky and ground light dimmed by the columns above and below, and
log T's slope fitted to its 8 light taps); the fragment shader applies the particle profile, the phase
function at its own view ray and the sun's light varied across the sprite as T varies (one J per
sprite spread a dense cloud's lit top over the darker cells below it: toward a 20° sun −13.7 % against
the march, now +4.4 %, ``tests/test_cloud_light.py``), and fades the
sprite out over its radius in front of the scene's depth (soft particles: no hard line where a sprite
meets terrain). Blending is premultiplied (ONE, ONE_MINUS_SRC_ALPHA), so "color"'s alpha stays
in [0, 1]; the depth test runs against the scene's "depth" with depth writes off.

Opacity: a sprite spreads its block's optical depth ``sigma_t × V × (density summed)`` (V the cell
volume) over the screen like the block's mass: an elliptical Gaussian with that mass's covariance on
the screen axes (its cells' spread plus each cell's, the quadratic B-spline's 1/4 cell² per axis),
cut to 0 where its long axis reaches the sprite's radius ``size_factor × max(cx, cz) × 2^L / 2``
(:mod:`.particle`). The ray march draws nearly the same mass (its trilinear hat: 1/6), so the image
no longer grows with the size factor once the radius holds the Gaussian (≥ ~3): the old fixed
``(1 − r²)²`` disc of the whole diameter spread the same optical depth over more pixels, and as
``1 − exp(−tau)`` is concave the cloud drew more opaque and brighter, +2.5 % at size 3 to +42 % at 6
(the +24..+72 % of level-of-detail blocks was the same: their disc was 2^L times wider). Level-of-
detail blocks now carry their own mass's spread, narrower than their spacing, so they ripple
(stripes 2^L cells apart) and stay off by default. Sprites under a pixel are drawn 1 pixel wide with their opacity scaled
by their area in pixels; sprites within one diameter of the near plane fade out linearly, so the
near plane never clips a visible sprite away (no pop).

On a GPU (``splat``) the same stages run in compute instead (:mod:`.splat`): binned into tiles and blended
front to back until opaque, the same image at the cost of the pixels covered rather than the overdraw.
"""
from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from atmos.camera import Camera, camera_matrices
from atmos.checks import bool_field, choice_field, int_field, num_field
from atmos.composition import CLOUD_DISTANCE, composition
from atmos.graph import PassBuilder, PassContext, RenderPass
from atmos.plugin import Plugin
from atmos.gpu import clamp_sampler
from atmos.plugins.clouds.light.ground import GROUND, ground_sun_pass
from atmos.plugins.clouds.volume.binding import bind_volume, unbind_volume
from atmos.plugins.clouds.volume.light import CloudLightSettings
from atmos.offscreen import CLOUD_COLOR, CLOUD_LOW_DISTANCE, MAX_DOWNSAMPLE, OffscreenLayer, low_size
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.sprites.segments import MAX_LEVEL, SegmentStats, select_segments, unpack
from atmos.plugins.clouds.sprites.splat import SpriteSplat
from atmos.plugins.clouds.volume.field_demand import field_demand
from atmos.plugins.clouds.volume.sets import CLOUD_SETS, CLOUD_VOLUME, CloudSets
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import bind_textures, write_uniforms


@dataclass(frozen=True)
class CloudRenderSettings(CloudLightSettings):
    """How the sprites are drawn (all live: a change shows on the next frame). The multiple-scattering
    octaves ``ms_attenuation``, ``ms_contribution``, ``ms_eccentricity`` and the diffusion field's weight
    ``ms_diffusion`` come first, inherited from :class:`~atmos.plugins.clouds.volume.light.CloudLightSettings`
    (shared with the ray-marched clouds)."""
    base_altitude: float | None = num_field(None, doc="world y of the layer's bottom (None: "
                                            "``CloudSettings.base_altitude``; placement: "
                                            ":mod:`atmos.plugins.clouds.volume.layout`)", optional=True)
    size_factor: float = num_field(3.0, 1e-3, 64.0, "sprite diameter in cells: where the mass's Gaussian "
                                   "footprint is cut off (≥ ~3 holds it and the image stays the same; smaller cuts "
                                   "it into a flatter disc; ~0 gives NaN sprites, 64 cells a whole volume)")
    sigma: float | None = num_field(None, 0.0, doc="extinction per cell length at density 1 (None: the "
                                    "simulation's ``CloudSettings.sigma``)", optional=True)
    frustum_culling: bool = bool_field(True, "skip columns outside the view frustum (:mod:`.segments`)")
    empty_space_skipping: bool = bool_field(True, "skip columns and blocks the simulation's max maps show "
                                            "empty (:mod:`.segments`)")
    max_point_size: float | None = num_field(None, 1.0, doc="caps sprite pixels (None: the GL limit)",
                                             optional=True)
    downsample: int = int_field(2, 1, MAX_DOWNSAMPLE, "draw the sprites off screen at 1/downsample of the frame "
                                "size and upsample them (:mod:`.offscreen`; 2 fills a quarter of the pixels; read "
                                "by the pass's ``setup`` every frame, so a change resizes the off-screen targets "
                                "on the next frame)")
    lod_pixels: float | None = num_field(None, 0.0, doc="level of detail: columns where a block of 2^L cells "
                                         "spans at most this many target pixels are drawn one sprite per block "
                                         "(L ≤ 2, :mod:`.segments`); None: every cell", lo_open=True, optional=True)
    splat: str = choice_field("auto", ("auto", "compute", "points"), "how the sprites reach the pixels: compute "
                              "(binned into 16×16 tiles, sorted and blended front to back until T < 1/255, "
                              ":mod:`.splat`: the cost follows the pixels covered, not the overdraw), points (one "
                              "blended point per sprite, back to front), auto: compute on a GPU, points on a software "
                              "renderer (where blending is as cheap as compute and the image the same)")
    enabled: bool = bool_field(True, "False declares nothing (the pass is culled, allocates nothing)")


class CloudRenderPlugin(Plugin):
    """Point-sprite clouds of the CloudsPlugin's simulation (its imported "cloud_sets"):
    ``CloudRenderPlugin(settings=None, **fields)`` with :class:`CloudRenderSettings`;
    ``configure(**changes)`` changes any of them live (next frame). After each frame ``stats``
    holds the :class:`SegmentStats` counters.
    """

    settings_class = CloudRenderSettings

    def __init__(self, settings: CloudRenderSettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.stats = SegmentStats()
        self.gpu = self.demand = None

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("CloudRenderPlugin needs an App with a GPU context (App(gpu))")
        self.gpu = app.gpu
        self.composition = composition(app)
        self.composition.writers.add("cloud_render")     # the sprites give the fog their own distance
        self.sprite_pass = app.graph.add_pass(CloudSpritePass(self))
        ground_sun_pass(app.graph)
        self.demand = field_demand(app)
        self.demand.readers.add(self)

    def cleanup(self, app) -> None:
        if self.demand is not None:
            self.demand.readers.discard(self)
        comp = getattr(self, "composition", None)
        if comp is not None:
            comp.writers.discard("cloud_render")

    def splats(self) -> bool:
        """Whether the sprites are splatted in compute (``splat``; auto: on a GPU, not a software renderer)."""
        mode = self.settings.splat
        return mode == "compute" or (mode == "auto" and not self.gpu.software)

    # -- shared with the reference ray marcher --------------------------------------------------
    def layout(self, sim: CloudSets) -> CloudLayout:
        """The volume's world placement now, column boxes padded by one cell's largest sprite radius
        (:func:`select_segments` scales it by a column's block size)."""
        cell, s = sim.settings.cell_size, self.settings
        return sim.layout(s.base_altitude, pad=0.5 * s.size_factor * max(cell[0], cell[2]))

    def extinction(self, sim: CloudSets) -> float:
        """Extinction per cube-root cell length at density 1 (the thesis's sigma)."""
        sigma = self.settings.sigma
        return float(sim.settings.sigma if sigma is None else sigma)

    def sigma_t(self, sim: CloudSets) -> float:
        """Extinction in 1/m at density 1 (the medium's, or this plugin's ``sigma`` override)."""
        return self.extinction(sim) / float(np.cbrt(np.prod(sim.settings.cell_size)))


COMMAND_BYTES = 20


def sprite_uniforms(plugin, sim, layout: CloudLayout, camera: Camera, aspect: float, height: int,
                    point_limit: float) -> dict:
    """The uniforms of ``clouds/sprites/sprite.vert`` but the volume's (:func:`bind_volume`), with the camera's
    position, near and far that the shaders read from the frame block (for the float64 reference)."""
    cell = np.asarray(layout.cell, np.float64)
    tau_scale = plugin.extinction(sim) * cell.prod() / np.cbrt(cell.prod())     # sigma_t × V
    settings = plugin.settings
    limit = point_limit if settings.max_point_size is None else min(point_limit, settings.max_point_size)
    basis = camera.basis()
    return {"volume_shape": tuple(map(int, layout.shape)), "group_size": tuple(layout.group),
            "layer_min": tuple(map(float, layout.lo)), "cell_size": tuple(map(float, cell)),
            "camera_cell": tuple(map(float, (np.asarray(camera.position, np.float64) - layout.lo) / cell)),
            "base_diameter": float(settings.size_factor * max(cell[0], cell[2])),
            "pixel_scale": float(height) / 2.0 * float(camera_matrices(camera, aspect).projection[1, 1]),
            "max_point_size": float(limit), "tau_scale": float(tau_scale), "near": float(camera.near),
            "far": float(camera.far),
            "camera_pos": tuple(map(float, camera.position)),
            "camera_right": tuple(map(float, basis[:, 0])),
            "camera_up": tuple(map(float, basis[:, 1]))}


class CloudSpritePass(RenderPass):
    """Pass "cloud_render" (phase translucent): reads "depth" and "cloud_sets", blends the sprites
    onto "color" (with ``downsample`` > 1 through the low-res "cloud_color"/"cloud_depth" it creates)."""
    name = "cloud_render"
    phase = "translucent"
    exclusive = CLOUD_VOLUME                # never on beside the ray march (a GraphError names both)
    clip_centres = False    # the splat drops sprites whose centre is off screen, as GL clips points (to compare)
    shared_sort = 2048      # the splat sorts tile lists up to this long in shared memory (16 KiB), longer in place

    def __init__(self, plugin: CloudRenderPlugin):
        self.plugin = plugin
        self.program = self.sampler = self.offscreen = self.splat = None
        self.instances = self.commands = self.vao = None
        self._group = self._uploaded = self._drawn = None   # _drawn: (segments, group, commands) written

    def setup_key(self) -> tuple:
        return (self.plugin.settings, self.plugin.composition.distance, self.plugin.gpu.size)

    def setup(self, builder: PassBuilder) -> None:
        if not self.plugin.settings.enabled:
            return                          # declares nothing: culled, allocates nothing
        builder.read(DEPTH)
        builder.read(CLOUD_SETS)
        builder.read(GROUND, access="uniform")
        downsample = self.plugin.settings.downsample
        distance = self.plugin.composition.distance
        splat = self.plugin.splats()
        onto = "storage" if splat and downsample == 1 else None     # the splat's blend writes the frame itself
        builder.read(COLOR, access=onto)    # blends onto it
        builder.write(COLOR, access=onto)
        if distance:                        # a media pass reads it: blend onto it (atmos.composition)
            builder.read(CLOUD_DISTANCE, access=onto)
            builder.write(CLOUD_DISTANCE, access=onto)
        if downsample > 1:
            OffscreenLayer.declare(builder, self.plugin.gpu.size, downsample, distance, storage=splat)

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="clouds/sprites/sprite.vert", fragment_shader="clouds/sprites/sprite.frag")
        self.offscreen = OffscreenLayer(gpu)
        self.sampler = clamp_sampler(gpu.ctx)
        limit = gpu.ctx.info.get("GL_POINT_SIZE_RANGE", (1.0, 64.0))[1]
        self.point_limit = float(limit)

    def _buffers(self, gpu, group, shape) -> None:
        """An instance buffer for every segment (made once per group size and volume shape)."""
        if self._group == (group, shape):
            return
        self._release_buffers()
        gx, gz = group
        grid = (-(-shape[0] // gx)) * (-(-shape[2] // gz)) * shape[1]
        self.instances = gpu.ctx.buffer(reserve=16 * grid)
        self.commands = gpu.ctx.buffer(reserve=COMMAND_BYTES * 16)
        self.vao = gpu.ctx.vertex_array(self.program, [(self.instances, "4i/i", "in_segment")])
        self._group = (group, shape)
        self._uploaded = self._drawn = None

    def _draw(self, segments: np.ndarray, group) -> None:
        """Every run of segments with one level and span as one instanced draw of its blocks, all in one
        multi-draw: commands (blocks per unit, segments, first vertex 0, first instance). moderngl
        strides array commands by 20 bytes (the indexed layout), hence the zero pad. The commands are
        written again only for other segments (select_segments hands back the same read-only array
        when nothing moved)."""
        if self._drawn is not None and self._drawn[0] is segments and self._drawn[1] == tuple(group):
            self.vao.render_indirect(self.commands, moderngl.POINTS, count=self._drawn[2])
            return
        code = segments[:, 3]
        starts = np.flatnonzero(np.r_[True, code[1:] != code[:-1]])
        counts = np.diff(np.r_[starts, len(code)])
        level, sx, sz = unpack(code[starts])
        blocks = (group[0] * sx >> level) * (group[1] * sz >> level)
        zero = np.zeros_like(counts)
        commands = np.stack([blocks, counts, zero, starts, zero], -1).astype(np.uint32)
        if commands.nbytes > self.commands.size:
            self.commands.orphan(commands.nbytes)
        self.commands.write(commands.tobytes())
        self._drawn = (segments, tuple(group), len(commands))
        self.vao.render_indirect(self.commands, moderngl.POINTS, count=len(commands))

    def execute(self, frame: PassContext) -> None:
        plugin = self.plugin
        settings = plugin.settings
        distance = frame.declares(CLOUD_DISTANCE)
        if not settings.enabled:
            return
        view, gpu = frame.view, frame.gpu
        sim: CloudSets = frame.resource(CLOUD_SETS)
        camera = view.camera
        aspect = view.aspect
        layout = plugin.layout(sim)
        matrices = camera_matrices(camera, aspect)
        view_proj = matrices.view_proj
        maps = sim.maps_of(sim.view()[0])
        ctx, p, factor = gpu.ctx, self.program, settings.downsample
        uniforms = sprite_uniforms(plugin, sim, layout, camera, aspect, low_size(gpu.size, factor)[1],
                                   self.point_limit)
        segments, plugin.stats = select_segments(
            layout, camera.position, view_proj if settings.frustum_culling else None,
            sim.max_maps() if settings.empty_space_skipping else None, maps.band_height,
            settings.lod_pixels, uniforms["pixel_scale"], MAX_LEVEL)
        if not len(segments):
            return
        self._buffers(gpu, layout.group, layout.shape)
        if segments is not self._uploaded:          # select_segments hands back the same array when nothing moved
            self.instances.write(segments.tobytes())
            self._uploaded = segments
        if plugin.splats():
            self._splat(frame, sim, layout, uniforms, segments, distance)
            return
        if factor == 1:
            fbo = frame.framebuffer(color=[COLOR, CLOUD_DISTANCE] if distance else [COLOR], depth=DEPTH)
            fbo.use()
        else:
            fbo = self.offscreen.begin(frame, factor, distance)
        # the soft particles' scene depth: the attached depth target's (sampled, never written)
        bind_textures(p, scene_depth=frame.resource(DEPTH if factor == 1 else self.offscreen.depth))
        write_uniforms(p, uniforms)
        fbo.depth_mask = False
        frame.blend_over()
        ctx.enable(moderngl.DEPTH_TEST | moderngl.PROGRAM_POINT_SIZE)
        ctx.depth_func = "<="          # a tiny near plane rounds far depths to 1.0: still in front of the sky
        bind_volume(p, sim, self.sampler, view.sun, settings.octaves, settings.ms_diffusion, layout.heights,
                    view.ground, ground_light=frame.resource(GROUND))
        try:
            self._draw(segments, layout.group)
        finally:
            unbind_volume(p, self.sampler)
        if factor > 1:
            self.offscreen.end(frame, factor, camera.near, camera.far, distance)

    def _splat(self, frame: PassContext, sim: CloudSets, layout: CloudLayout, uniforms: dict, segments, distance: bool) -> None:
        """The sprites splatted in compute (:mod:`.splat`) onto "color" (and "cloud_distance"), or off screen
        into the low-res targets and composited."""
        settings, view, gpu = self.plugin.settings, frame.view, frame.gpu
        factor = settings.downsample
        if self.splat is None:
            self.splat = SpriteSplat(gpu)
        if factor == 1:
            size, depth = gpu.size, DEPTH
            images = {"color_image": frame.image(COLOR)}
            if distance:
                images["distance_image"] = frame.image(CLOUD_DISTANCE)
        else:
            self.offscreen.begin(frame, factor, distance, clear=False)     # the blend writes every low-res texel
            frame.reset_state()
            size, depth = low_size(gpu.size, factor), self.offscreen.depth
            images = {"color_image": frame.image(CLOUD_COLOR)}
            if distance:
                images["distance_image"] = frame.image(CLOUD_LOW_DISTANCE)
        count = int(self.splat.count)
        defines = {"setup": {"SPLAT_CLIP_CENTRES": int(self.clip_centres), "SPLAT_COUNT": count}, "scan": None,
                   "bin": None, "blend": {"SPLAT_OVER": int(factor == 1), "SPLAT_DISTANCE": int(distance),
                                          "SPLAT_SHARED_SORT": int(self.shared_sort), "SPLAT_COUNT": count}}
        programs = tuple(gpu.program(compute_shader=f"clouds/sprites/splat_{stage}.comp", defines=defines[stage])
                         for stage in defines)
        lit = (programs[0], programs[3])
        for p in lit:
            write_uniforms(p, uniforms)
            bind_volume(p, sim, self.sampler, view.sun, settings.octaves, settings.ms_diffusion, layout.heights,
                        view.ground, ground_light=frame.resource(GROUND))
        try:
            self.splat.draw(frame, programs, self.instances, len(segments), layout.group, self.plugin.stats.sprites,
                            size, {"scene_depth": depth}, images)
        finally:
            for p in lit:
                unbind_volume(p, self.sampler)
        if factor > 1:
            self.offscreen.end(frame, factor, view.camera.near, view.camera.far, distance)

    def _release_buffers(self) -> None:
        for obj in (self.vao, self.instances, self.commands):
            if obj is not None:
                obj.release()
        self.vao = self.instances = self.commands = None
        self._group = self._uploaded = self._drawn = None   # _drawn: (segments, group, commands) written

    def release(self) -> None:
        self._release_buffers()
        if self.splat is not None:
            self.splat.release()
            self.splat = None
        if self.sampler is not None:
            self.sampler.release()
        self.sampler = None
