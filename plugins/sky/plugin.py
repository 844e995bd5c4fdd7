"""SkyPlugin and its pass: the Preetham sky with sun disc, night and stars as the scene's background."""
from __future__ import annotations

from atmos.camera import set_camera_uniforms
from atmos.graph import FullscreenPass, PassContext
from atmos.plugin import Plugin
from atmos.plugins.sky.settings import SkySettings
from atmos.plugins.sky.shader import set_sky_uniforms, sky_defines
from atmos.render_core import DEPTH, where_nothing_was_drawn


class SkyPass(FullscreenPass):
    """Writes the sky into every pixel of ``color`` where nothing was drawn (depth 1; later passes draw
    over it), from the Sun resource."""
    name = "sky"
    phase = "sky"
    fragment = "sky/sky.frag"
    vertex = "lib/fullscreen_far.vert"
    reads = (DEPTH,)

    def defines(self) -> dict:
        return sky_defines()

    def execute(self, frame: PassContext) -> None:
        view, p = frame.view, self.program
        where_nothing_was_drawn(frame)
        camera = view.camera
        set_camera_uniforms(p, camera, view.aspect)      # view_basis
        set_sky_uniforms(p, self.plugin.settings, view.sun.direction, view.sun.color, view.time,
                         camera.fov_y / max(1, view.size[1]))
        frame.fullscreen(p)


class SkyPlugin(Plugin):
    """The Preetham analytic sky (pass "sky"): ``SkyPlugin(settings=None, **fields)`` with
    :class:`SkySettings`; ``configure(**changes)`` changes any of them live (next frame)."""

    settings_class = SkySettings

    def build(self, app) -> None:
        app.graph.add_pass(SkyPass(self))
