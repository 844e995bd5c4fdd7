"""The march mode of the light shafts: sun light scattered by a thin haze along each view ray,
shadowed by the clouds through the ground shadows' density maps (shaders/light_shafts/march.comp,
a compute pass), at low resolution and upsampled by depth with the off-screen clouds' draws
(:class:`~atmos.offscreen.OffscreenLayer`). Reference: :func:`.reference.march_shafts`."""
from __future__ import annotations

import numpy as np

from atmos.blue_noise import blue_noise_texture
from atmos.composition import CLOUD_DISTANCE
from atmos.graph import PassBuilder, PassContext, work_groups
from atmos.lighting import unit_sun
from atmos.plugins.clouds import CLOUD_SETS, FAR_FIELD, CloudSets, column_uniforms
from atmos.plugins.clouds.shadows.shadow_map import SHADOW_MAP, SHADOW_SPACE, cloud_extinctions, use_shadow_map
from atmos.offscreen import OffscreenLayer
from atmos.plugins.light_shafts.settings import FLOAT32_MAX
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import bind_textures, write_uniforms

SHAFT_COLOR = "light_shafts_march"     # low-res (in-scattered light, transmittance)
SHAFT_DEPTH = "light_shafts_depth"     # low-res farthest scene depth


def march_irradiance(sun, settings) -> np.ndarray | None:
    """The sun irradiance the haze is lit by, ``sun_intensity × Sun.color`` × smoothstep(0,
    ``horizon_fade``, sun height), at most float32's largest finite value (its uniform); None when
    nothing would show (no sun, below the horizon, black)."""
    s = unit_sun(sun.direction)
    if s is None or s[1] <= 0.0 or settings.scattering == 0.0:
        return None
    x = min(float(s[1]) / settings.horizon_fade, 1.0)
    e = settings.sun_intensity * x * x * (3.0 - 2.0 * x) * np.asarray(sun.color, np.float64)
    return np.minimum(e, FLOAT32_MAX) if e.max() > 0.0 else None


class MarchedShafts:
    """The march's declarations and draws for a LightShaftsPass (programs belong to the GpuContext)."""

    exact = False       # True: the column sums at every step instead of the cloud shadow map (benchmarks)

    def __init__(self, gpu):
        self.gpu = gpu
        self.offscreen = OffscreenLayer(gpu, SHAFT_COLOR, SHAFT_DEPTH)
        self.jitter = None                  # the blue-noise tile of the rays' start offsets (first use)

    def release(self) -> None:
        if self.jitter is not None:
            self.jitter.release()
            self.jitter = None

    def program(self, far_field: bool, fog=None, aerial=None, shader: str = "light_shafts/march.comp",
                composite: bool = False):
        """``shader`` (the march, or the froxels' fill and apply) with the far field's shadows beyond the volume
        (column.glsl's CLOUD_FAR_FIELD) or without; ``fog`` (the FogMedium): the variant that shadows the fog's
        in-scatter (SHAFT_FOG); ``aerial`` (the SkyLight): the variant that shadows the sky's aerial
        perspective (SHAFT_AERIAL); with ``composite`` the froxels' apply that composites them too
        (SHAFT_FOG_COMPOSITE, SHAFT_AIR_COMPOSITE)."""
        defines = {}
        if composite and fog is not None:
            defines["SHAFT_FOG_COMPOSITE"] = 1
        if composite and aerial is not None:
            defines.update(SHAFT_AIR_COMPOSITE=1, **aerial.pixel_defines())
        if self.exact:
            defines.update(SHAFT_EXACT_SHADOWS=1, **({"CLOUD_FAR_FIELD": 1} if far_field else {}))
        if aerial is not None:
            defines.update(SHAFT_AERIAL=1, **aerial.aerial_defines())
        if fog is not None:
            defines.update(SHAFT_FOG=1, **fog.defines())
        return self.gpu.program(defines or None, compute_shader=shader)

    @classmethod
    def declare(cls, builder: PassBuilder, size, factor: int, clouds: bool, far_field: bool = False, fog=None,
                aerial=None) -> None:
        """``far_field``: the graph imports a CloudFarFieldPlugin's layer; the rays see its shadows too.
        ``fog``: the App's FogMedium; its clouds' own distance is read when the fog reads one.
        ``aerial``: the SkyLight whose aerial perspective the march shadows (its LUTs are read, and the
        clouds' own distance when its pass reads one)."""
        OffscreenLayer.declare(builder, size, factor, color=SHAFT_COLOR, depth=SHAFT_DEPTH, storage=True)
        builder.read(DEPTH)
        builder.read(COLOR)
        builder.write(COLOR)
        cls.declare_medium(builder, clouds, far_field, fog, aerial)

    @classmethod
    def declare_medium(cls, builder: PassBuilder, clouds: bool, far_field: bool, fog, aerial) -> None:
        """What light_shafts/medium.glsl reads: the clouds' shadows, the fog's and the air's inputs."""
        if clouds:
            builder.read(CLOUD_SETS)
            if not cls.exact:
                builder.read(SHADOW_MAP)
                builder.read(SHADOW_SPACE)
            if far_field:
                builder.read(FAR_FIELD)
        if fog is not None and fog.reads_cloud_distance:
            builder.read(CLOUD_DISTANCE)
        if aerial is not None:
            aerial.declare_aerial(builder)
            if aerial.reads_cloud_distance:
                builder.read(CLOUD_DISTANCE)          # (a second read of the same is the same read)

    def execute(self, frame: PassContext, settings, clouds: bool, fog=None, aerial=None) -> None:
        irradiance = march_irradiance(frame.view.sun, settings)
        if irradiance is None:
            return
        factor = settings.downsample
        self.offscreen.begin(frame, factor, clear=False)      # the march writes every low-res texel
        frame.reset_state()
        p = self.program(clouds and frame.declares(FAR_FIELD), fog, aerial)
        if self.jitter is None:
            self.jitter = blue_noise_texture(self.gpu.ctx)
        self.set_medium(frame, p, settings, clouds, irradiance, fog, aerial)    # first: it may prepare the far field
        bind_textures(p, low_depth=frame.resource(SHAFT_DEPTH), blue_noise=self.jitter)
        write_uniforms(p, steps=settings.steps, factor=factor, frame_size=tuple(float(v) for v in frame.view.size))
        shafts = frame.image(SHAFT_COLOR)
        frame.dispatch(p, work_groups(shafts.size, (8, 8)), images={"shafts": shafts})
        self.offscreen.end(frame, factor, frame.view.camera.near, frame.view.camera.far, medium=True)

    def set_medium(self, frame: PassContext, p, settings, clouds: bool, irradiance, fog=None, aerial=None) -> None:
        """Every uniform and texture of light_shafts/medium.glsl: the clouds' shadows (the shadow map, or
        the column sums and the far field), the haze, the fog's and the air's."""
        view = frame.view
        far_field = clouds and frame.declares(FAR_FIELD)
        if clouds and frame.declares(SHADOW_MAP):
            use_shadow_map(frame, p, *cloud_extinctions(frame))
        elif clouds:
            sim: CloudSets = frame.resource(CLOUD_SETS)
            layer = frame.resource(FAR_FIELD) if far_field else None
            if layer is not None:               # first: its measure dispatches programs of its own
                layer.prepare(view, sim)
            column_uniforms(p, sim, sim.layout(), sim.settings.sigma)
            if layer is not None:
                layer.use(p, view, sim)
        write_uniforms(p, has_clouds=int(clouds), irradiance=tuple(map(float, irradiance)),
                       lobes=settings.phase.lobes, scattering=settings.scattering, max_distance=settings.max_distance)
        if fog is not None:
            self.fog_uniforms(frame, p, fog, settings)
        if aerial is not None:
            self.aerial_uniforms(frame, p, aerial)

    @staticmethod
    def fog_uniforms(frame: PassContext, program, fog, settings) -> None:
        """The fog's factor and colour (as its own pass sets them) and its clouds' distance."""
        fog.set_uniforms(program, frame.view)
        bind_cloud_distance(frame, program)
        write_uniforms(program, fog_sun_share=settings.fog_sun_share)

    @staticmethod
    def aerial_uniforms(frame: PassContext, program, sky) -> None:
        """The sky's atmosphere (its LUTs bound, the camera's radius) and the clouds' distance."""
        sky.set_aerial_uniforms(frame, program)
        bind_cloud_distance(frame, program)


def bind_cloud_distance(frame: PassContext, program) -> None:
    """The clouds' own distance when the pass declared it (``has_cloud_distance``)."""
    clouds = frame.declares(CLOUD_DISTANCE)
    if clouds:
        bind_textures(program, cloud_distance=frame.resource(CLOUD_DISTANCE))
    write_uniforms(program, has_cloud_distance=int(clouds))
