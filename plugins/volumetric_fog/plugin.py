"""VolumetricFogPlugin and its pass: the FBM medium ray-marched over the scene, occluded by depth."""
from __future__ import annotations

import numpy as np

from atmos.camera import Camera, set_camera_uniforms
from atmos.checks import plugin_params
from atmos.graph import FullscreenPass, PassContext
from atmos.lighting import Sun, scene_sun, sun_and_day
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH
from atmos.plugins.volumetric_fog.params import FogParams


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


class VolumetricFogPass(FullscreenPass):
    """Reads ``depth``, blends (in-scattered light, transmittance) over ``color`` with ONE, SRC_ALPHA;
    alpha (the sky occlusion of :mod:`atmos.render_core`) kept: the medium tints the sky, it does not hide it."""
    name = "volumetric_fog"
    fragment = "volumetric_fog/fog.frag"
    reads = (DEPTH,)

    def execute(self, frame: PassContext) -> None:
        app, gpu, p = frame.data["app"], frame.gpu, self.program
        frame.framebuffer(color=[COLOR]).use()
        frame.blend_transmittance()
        frame.texture(DEPTH).use(0)
        set_camera_uniforms(p, app.resource(Camera), gpu.size[0] / gpu.size[1])
        set_medium_uniforms(p, self.plugin.params, scene_sun(app), self.plugin.time(app))
        frame.fullscreen(p)


class VolumetricFogPlugin(Plugin):
    """Ray-marched FBM fog; ``FogParams`` fields as keyword arguments (or ``params=``).

    ``configure(**changes)`` changes settings at run time: all are checked before any is applied.
    The noise drifts with the App's clock (``clock.frame_time``) unless ``animate=False``.
    """

    def __init__(self, params: FogParams | None = None, animate: bool = True, **settings):
        self.params = plugin_params("VolumetricFogPlugin", FogParams, params, settings)
        self.animate = bool(animate)

    def configure(self, **changes) -> FogParams:
        """Replace settings at once (checked together; on error nothing changes); returns the new params."""
        self.params = self.params.replace(**changes)
        return self.params

    def time(self, app) -> float:
        return float(app.clock.frame_time) if self.animate else 0.0

    def build(self, app) -> None:
        app.graph.add_pass(VolumetricFogPass(self))
