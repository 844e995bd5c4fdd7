"""The fog post-process pass: reads ``depth``, blends the fog over ``color`` by eq. (1)."""
from __future__ import annotations

import math

import numpy as np

from atmos.lighting import sun_and_day
from atmos.composition import CLOUD_DISTANCE, MEDIA_LIGHT, MEDIA_TRANSMITTANCE, media_targets
from atmos.graph import PassBuilder, PassContext, RenderPass, work_groups
from atmos.graph.frame import BLEND_TRANSMITTANCE, blend
from atmos.plugins.fog.noise import NoiseVolumes, octave_key
from atmos.plugins.fog.settings import MODES
from atmos.plugins.fog.sky_color import SAMPLES, sky_sun
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import write_uniforms

FRAGMENT = "fog/fog.frag"
COMPUTE = "fog/fog.comp"
VERTEX = "lib/fullscreen.vert"


def fog_program(gpu, settings, from_depth: bool, clouds: bool = False, media: int = 0):
    """The fog program for ``settings`` from ``gpu``'s cache (one variant per mode, octave count,
    noise kind, colour source, whether clouds give their own distance and whether it also writes the
    media targets, :mod:`atmos.composition`: 1 blended onto them, 2 stored as their first writer)."""
    defines = {"FOG_MODE": MODES[settings.mode], "FOG_OCTAVES": settings.octaves,
               "FOG_PROCEDURAL": int(settings.noise == "procedural"), "FOG_FROM_DEPTH": int(from_depth),
               "FOG_CLOUDS": int(clouds), "FOG_SKY_COLOR": int(settings.color_from == "sky"),
               "FOG_HORIZON_SAMPLES": SAMPLES, "LOCAL_MEDIA": int(media), "FOG_SUN": int(settings.sun_scattering > 0)}
    if from_depth:                           # the graph's pass: a compute pass compositing in place
        return gpu.program(defines, compute_shader=COMPUTE)
    return gpu.program(defines, vertex_shader=VERTEX, fragment_shader=FRAGMENT)



def sun_light(sun, settings) -> tuple[np.ndarray, np.ndarray]:
    """(unit direction toward the sun, the light the fog scatters from it: Sun.color × sun_scattering,
    faded out as the sun sets, :func:`atmos.lighting.sun_and_day`); zeros without a sun."""
    if sun is None or settings.sun_scattering == 0.0:
        return np.array([0.0, 1.0, 0.0]), np.zeros(3)
    direction, day = sun_and_day(sun)
    return np.asarray(direction, np.float64), np.asarray(sun.color, np.float64) * settings.sun_scattering * day


def set_fog_uniforms(prog, settings, time: float, table=None, sun=None) -> None:
    """The factor's uniforms (fog/factor.glsl) and the fog colour and sky handling (fog/fog.frag);
    ``table``: ``color_from="sky"``'s horizon by angle from ``sun`` (:func:`.sky_color.shader_table`);
    ``sun`` (a Sun; None: none): the sunlight it scatters (``sun_scattering``)."""
    if table is not None:
        write_uniforms(prog, fog_horizon=table.tobytes(), fog_sky_sun=sky_sun(sun))
    direction, light = sun_light(sun, settings)
    write_uniforms(prog, fog_sun_light=tuple(light), fog_sun_dir=tuple(direction), fog_lobes=settings.phase.lobes)
    write_uniforms(prog, fog_density=settings.density, fog_start=settings.start, fog_end=settings.end,
                   fog_color=settings.fog_color, fog_sky_keep=int(settings.sky == "keep"),
                   fog_height_base=settings.height_base, fog_scale_height=settings.scale_height)
    if not settings.heterogeneous:
        return
    periods = list(settings.resolutions) + [2] * (4 - len(settings.resolutions))
    write_uniforms(prog, fog_time=float(time), fog_tile=settings.tile_size, fog_amplitude=settings.amplitude,
                   fog_period=periods, fog_key=[octave_key(settings.seed, i) for i in range(4)],
                   fog_wind=list(settings.winds),
                   fog_turn=[(math.cos(a), math.sin(a)) for a in settings.turns])


def draw_state(ctx) -> None:
    """No depth test; blend (ONE, SRC_ALPHA) on colour: target = rgb + a * target; alpha kept.

    ``color.a`` is the sky occlusion (:mod:`atmos.render_core`); fog is a medium, not an occluder, so
    a fogged sky (``sky="fog"``) is still sky there: the light shafts see it by its colour, which the
    fog has already pulled toward the fog colour (only what stays brighter than their threshold casts)."""
    ctx.disable(ctx.DEPTH_TEST)
    blend(ctx, BLEND_TRANSMITTANCE)          # what PassContext.blend_transmittance sets in the graph


def restore_state(ctx) -> None:
    ctx.disable(ctx.BLEND)
    ctx.blend_func = ctx.SRC_ALPHA, ctx.ONE_MINUS_SRC_ALPHA


class FogPass(RenderPass):
    """The fog over the scene, one compute invocation per pixel composited onto the colour in place
    (fog/fog.comp): distance and position from the scene depth and the camera. Culled while another
    pass composites the fog (:meth:`.medium.FogMedium.composite_elsewhere`)."""
    name = "fog"
    phase = "media"

    def __init__(self, plugin):
        self.plugin = plugin
        self.gpu = None
        self.volumes: NoiseVolumes | None = None
        self.makes_media = False               # it creates the media targets (setup)

    def setup_key(self) -> tuple:
        comp = self.plugin.composition
        return (comp.distance, comp.media, comp.media_first == self.name, self.plugin.gpu.size,
                self.plugin.medium.composited_elsewhere)

    def setup(self, builder: PassBuilder) -> None:
        comp = self.plugin.composition
        self.makes_media = False
        if self.plugin.medium.composited_elsewhere:
            return                              # declares nothing: culled
        builder.read(DEPTH)
        builder.read(COLOR, access="storage")          # composites onto it in place
        builder.write(COLOR, access="storage")
        if comp.distance:                      # the clouds' own distance (atmos.composition)
            builder.read(CLOUD_DISTANCE)
        self.makes_media = comp.media and comp.media_first == self.name
        if self.makes_media:                   # the only local medium: it makes the media targets
            for name, desc, _ in media_targets(self.plugin.gpu.size):
                builder.create(name, desc, access="storage")
        elif comp.media:                       # the aerial perspective mixes the air with it
            for name in (MEDIA_LIGHT, MEDIA_TRANSMITTANCE):
                builder.read(name, access="storage")
                builder.write(name, access="storage")

    def prepare(self, gpu) -> None:
        self.gpu = gpu
        self._sync(self.plugin.settings)

    def _sync(self, settings, clouds: bool = False, media: int = 0):
        """Compile the variant and (re)make noise volumes when the settings need other ones (``media``:
        0 none, 1 blended onto the media targets, 2 stored into them)."""
        prog = fog_program(self.gpu, settings, from_depth=True, clouds=clouds, media=media)
        wants = settings.heterogeneous and settings.noise == "texture"
        if self.volumes is not None and (not wants or not self.volumes.matches(settings)):
            self.volumes.release()
            self.volumes = None
        if wants and self.volumes is None:
            self.volumes = NoiseVolumes(self.gpu, settings)
        return prog

    def execute(self, frame: PassContext) -> None:
        view = frame.view
        settings = self.plugin.settings
        clouds, media = frame.declares(CLOUD_DISTANCE), frame.declares(MEDIA_LIGHT)
        prog = self._sync(settings, clouds, 2 if self.makes_media else int(media))
        textures = {"scene_depth": DEPTH}
        if clouds:
            textures["cloud_distance"] = CLOUD_DISTANCE
        if self.volumes is not None:
            self.volumes.bind(prog)
        set_fog_uniforms(prog, settings, view.time + settings.time_offset, self.plugin.sky_table(view), view.sun)
        images = {"color_image": COLOR}
        if media:
            images.update(media_light_image=MEDIA_LIGHT, media_transmittance_image=MEDIA_TRANSMITTANCE)
        color = frame.image(COLOR)
        frame.dispatch(prog, work_groups(color.size, (8, 8)), textures=textures, images=images)

    def release(self) -> None:
        if self.volumes is not None:
            self.volumes.release()
            self.volumes = None
