"""SkyPlugin and its pass: the Preetham sky with sun disc, night and stars as the scene's background."""
from __future__ import annotations

from atmos.camera import Camera, set_camera_uniforms
from atmos.checks import plugin_params
from atmos.graph import FullscreenPass, PassContext
from atmos.lighting import scene_sun, sun_and_day
from atmos.plugin import Plugin
from atmos.plugins.sky.params import SkyParams
from atmos.plugins.sky.shader import set_sky_uniforms, sky_defines
from atmos.render_core import COLOR


class SkyPass(FullscreenPass):
    """Writes the sky into every pixel of ``color`` (later passes draw over it), from the Sun resource."""
    name = "sky"
    fragment = "sky/sky.frag"

    def defines(self) -> dict:
        return sky_defines()

    def execute(self, frame: PassContext) -> None:
        app, gpu, p = frame.data["app"], frame.gpu, self.program
        frame.framebuffer(color=[COLOR]).use()
        camera = app.resource(Camera)
        set_camera_uniforms(p, camera, gpu.size[0] / gpu.size[1])      # view_basis
        sun = scene_sun(app)
        s, _ = sun_and_day(sun)
        set_sky_uniforms(p, self.plugin.params, s, sun.color, app.clock.frame_time,
                         camera.fov_y / max(1, gpu.size[1]))
        frame.fullscreen(p)


class SkyPlugin(Plugin):
    """The Preetham analytic sky (pass "sky"); ``SkyParams`` fields as keyword arguments (or ``params=``).

    ``configure(**changes)`` changes settings at run time, all checked before any is applied.
    """

    def __init__(self, params: SkyParams | None = None, **settings):
        self.params = plugin_params("SkyPlugin", SkyParams, params, settings)

    def configure(self, **changes) -> SkyParams:
        self.params = self.params.replace(**changes)
        return self.params

    def build(self, app) -> None:
        app.graph.add_pass(SkyPass(self))
