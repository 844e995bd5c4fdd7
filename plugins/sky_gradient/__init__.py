"""A cheap analytic sky: horizon-to-zenith gradient, a sun disc and glow. Draws the whole background."""
from atmos.graph import FullscreenPass, PassContext
from atmos.lighting import set_scene_uniforms
from atmos.plugin import Plugin
from atmos.render_core import COLOR


class SkyGradientPass(FullscreenPass):
    name = "sky_gradient"
    fragment = "sky_gradient/sky.frag"

    def execute(self, frame: PassContext) -> None:
        app, gpu = frame.data["app"], frame.gpu
        frame.framebuffer(color=[COLOR]).use()
        set_scene_uniforms(self.program, app, gpu.size[0] / gpu.size[1])
        self.program["zenith"].value = self.plugin.zenith
        self.program["horizon"].value = self.plugin.horizon
        self.program["ground"].value = self.plugin.ground
        frame.fullscreen(self.program)


class SkyGradientPlugin(Plugin):
    """Sky colours (linear HDR): ``zenith`` overhead, ``horizon`` at eye level, ``ground`` below it."""

    def __init__(self, zenith=(0.15, 0.35, 0.8), horizon=(0.75, 0.85, 1.0), ground=(0.35, 0.33, 0.3)):
        self.zenith, self.horizon, self.ground = zenith, horizon, ground

    def build(self, app) -> None:
        app.graph.add_pass(SkyGradientPass(self))
