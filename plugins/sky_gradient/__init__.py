"""A cheap analytic sky: horizon-to-zenith gradient, a sun disc and glow. Draws the whole background."""
from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_vec
from atmos.graph import FullscreenPass, PassContext
from atmos.scene_uniforms import set_scene_uniforms
from atmos.plugin import Plugin
from atmos.render_core import DEPTH, where_nothing_was_drawn


@dataclass(frozen=True)
class SkyGradientSettings(CheckedSettings):
    """Sky colours (linear HDR, non-negative): ``zenith`` overhead, ``horizon`` at eye level,
    ``ground`` below it. All live."""
    zenith: tuple = (0.15, 0.35, 0.8)
    horizon: tuple = (0.75, 0.85, 1.0)
    ground: tuple = (0.35, 0.33, 0.3)

    def __post_init__(self):
        o = "SkyGradientSettings"
        self.store({name: check_vec(o, name, getattr(self, name), 3, "non-negative")
                    for name in ("zenith", "horizon", "ground")})


class SkyGradientPass(FullscreenPass):
    """The gradient where nothing was drawn (depth 1)."""
    name = "sky_gradient"
    phase = "sky"
    fragment = "sky_gradient/sky.frag"
    vertex = "lib/fullscreen_far.vert"
    reads = (DEPTH,)

    def execute(self, frame: PassContext) -> None:
        where_nothing_was_drawn(frame)
        set_scene_uniforms(self.program, frame.view)
        settings = self.plugin.settings
        self.program["zenith"].value = settings.zenith
        self.program["horizon"].value = settings.horizon
        self.program["ground"].value = settings.ground
        frame.fullscreen(self.program)


class SkyGradientPlugin(Plugin):
    """The gradient sky: ``SkyGradientPlugin(settings=None, **fields)`` with :class:`SkyGradientSettings`;
    ``configure(**changes)`` changes any of them live (next frame)."""

    settings_class = SkyGradientSettings

    def build(self, app) -> None:
        app.graph.add_pass(SkyGradientPass(self))
