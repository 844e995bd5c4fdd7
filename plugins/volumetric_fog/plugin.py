"""VolumetricFogPlugin and its pass: the FBM medium ray-marched over the scene, occluded by depth."""
from __future__ import annotations

import numpy as np

from atmos.camera import Camera, set_camera_uniforms
from atmos.graph import PassBuilder, PassContext, RenderPass
from atmos.lighting import Sun
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH
from atmos.plugins.volumetric_fog.params import FogParams


def sun_and_day(sun: Sun) -> tuple[np.ndarray, float]:
    """(unit direction toward the sun, daylight 0..1 = smoothstep(-0.15, 0.1, sun height) like the sky)."""
    s = np.asarray(sun.direction, np.float64)
    norm = np.linalg.norm(s)
    s = s / norm if np.isfinite(norm) and norm > 1e-9 else np.array([0.0, 1.0, 0.0])
    day = float(np.clip((s[1] + 0.15) / 0.25, 0.0, 1.0))
    return s, day * day * (3 - 2 * day)


def sun_terms(sun: Sun, params: FogParams):
    """(unit direction toward the sun, sun_light, ambient_light): the sun fades out below the horizon."""
    s, day = sun_and_day(sun)
    sun_light = np.asarray(sun.color, np.float64) * params.scattering * day
    ambient_light = np.asarray(params.ambient) * (0.1 + 0.9 * day)
    return s, sun_light, ambient_light


def set_medium_uniforms(program, params: FogParams, sun: Sun, time: float) -> None:
    """Write every uniform of ``volumetric_fog/medium.glsl``."""
    s, sun_light, ambient_light = sun_terms(sun, params)
    values = {"center": params.center, "scale": params.scale, "bias": params.bias, "falloff": params.falloff,
              "frequency": params.frequency, "wind": params.wind, "time": float(time),
              "octaves": params.octaves, "seed": params.seed, "absorption": params.absorption,
              "steps": params.steps, "light_steps": params.light_steps, "light_step": params.light_step,
              "max_distance": params.max_distance, "sun_dir": tuple(s), "sun_light": tuple(sun_light),
              "ambient_light": tuple(ambient_light)}
    for name, value in values.items():
        if name in program:          # the compiler drops uniforms it proves unused
            program[name].value = value


class VolumetricFogPass(RenderPass):
    """Reads ``depth``, blends (in-scattered light, transmittance) over ``color`` with ONE, SRC_ALPHA."""
    name = "volumetric_fog"

    def __init__(self, plugin: "VolumetricFogPlugin"):
        self.plugin = plugin
        self.program = None

    def setup(self, builder: PassBuilder) -> None:
        builder.read(DEPTH)
        builder.write(COLOR)

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="volumetric_fog/fog.frag")

    def execute(self, frame: PassContext) -> None:
        app, gpu, p = frame.data["app"], frame.gpu, self.program
        ctx = gpu.ctx
        frame.framebuffer(color=[COLOR]).use()
        ctx.disable(ctx.DEPTH_TEST)
        ctx.enable(ctx.BLEND)
        ctx.blend_func = ctx.ONE, ctx.SRC_ALPHA, ctx.ZERO, ctx.ONE     # alpha of "color" stays
        frame.texture(DEPTH).use(0)
        set_camera_uniforms(p, app.resource(Camera), gpu.size[0] / gpu.size[1])
        set_medium_uniforms(p, self.plugin.params, app.get_resource(Sun) or Sun(), self.plugin.time(app))
        frame.fullscreen(p)
        ctx.disable(ctx.BLEND)
        ctx.blend_func = ctx.SRC_ALPHA, ctx.ONE_MINUS_SRC_ALPHA


class VolumetricFogPlugin(Plugin):
    """Ray-marched FBM fog; ``FogParams`` fields as keyword arguments (or ``params=``).

    ``configure(**changes)`` changes settings at run time: all are checked before any is applied.
    The noise drifts with the App's clock (``clock.frame_time``) unless ``animate=False``.
    """

    def __init__(self, params: FogParams | None = None, animate: bool = True, **settings):
        base = params if params is not None else FogParams()
        if params is not None and not isinstance(params, FogParams):
            raise ValueError(f"params must be a FogParams, got {type(params).__name__}")
        self.params = base.replace(**settings) if settings else base
        self.animate = bool(animate)

    def configure(self, **changes) -> FogParams:
        """Replace settings at once (checked together; on error nothing changes); returns the new params."""
        self.params = self.params.replace(**changes)
        return self.params

    def time(self, app) -> float:
        return float(app.clock.frame_time) if self.animate else 0.0

    def build(self, app) -> None:
        app.graph.add_pass(VolumetricFogPass(self))
